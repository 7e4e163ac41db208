#pragma once
/// @file
/// Where the running program is installed, and the one rule by which every rigger binary finds the files
/// it reads at run time. Nothing here uses a path of the source tree compiled in.
///
/// Layout (the same in an installed prefix and in the build tree, which CMake stages alike):
///   <prefix>/bin/<program>             services, riggerctl, rigger-compose and the other tools
///   <prefix>/tests/, <prefix>/bench/   test and benchmark binaries (build tree only)
///   <prefix>/share/rigger/             the data folder, data_dir(): cyclonedds.xml; deploy/ (compose
///                                      files, configurations, the cell and its STEP models), recipes/,
///                                      test/data/ (the scripted executor's skill library) at the same
///                                      relative paths as in the repository; web/ (the console's pages);
///                                      cell_sim/cell.xml (the MuJoCo model)
///
/// Finding a file (find_data_path; config_path for a file named by a configuration key):
///   - an absolute path is used as it is;
///   - a relative path named in a configuration file is looked up in that file's folder, then in
///     data_dir() (so "../cell/simulated_cell.json" and "deploy/cell/simulated_cell.json" both work);
///   - a default, named by no configuration, is looked up in data_dir() alone.
/// Never the working directory, never the source tree: an installed tree works from any folder and
/// after it has been moved.

#include <filesystem>
#include <string>
#include <vector>

namespace rigger {

class Config;

/// The simulated cell's file, in the data folder: the default of every service that reads a cell file.
inline constexpr const char* kDefaultCellFile = "deploy/cell/simulated_cell.json";

/// The running executable (from /proc/self/exe); empty when it cannot be read.
std::filesystem::path executable_path();

/// The installation's data folder `<prefix>/share/rigger`, where `<prefix>` is the folder above the
/// one holding `executable` (default: the running executable). Empty when `executable` is empty.
std::filesystem::path data_dir(const std::filesystem::path& executable = executable_path());

/// Where find_data_path looked for a file and what it found.
struct DataPath {
  std::filesystem::path path;                ///< the first candidate that exists, else the first candidate
  std::vector<std::filesystem::path> tried;  ///< every candidate, in the order tried
  bool found = false;                        ///< `path` exists (a file or a folder)

  /// "<name> not found (tried <a>, then <b>)": for the caller's error, which says what named it.
  std::string not_found(const std::filesystem::path& name) const;
};

/// Applies the rule above to `name`. `named_in`: the configuration file that names it (empty for a
/// default); `data`: the data folder (default data_dir()). Reads the file system; never throws.
DataPath find_data_path(const std::filesystem::path& name, const std::filesystem::path& named_in = {},
                        const std::filesystem::path& data = data_dir());

/// The file `config` was read from (Config::load), whose folder its relative paths are looked up in;
/// empty when it was parsed from text.
std::filesystem::path config_file_of(const Config& config);

/// The file or folder named at `key` of `config`, found by the rule above (a relative path: beside the
/// configuration's file, then in data_dir()); when `key` is absent, `fallback` in data_dir().
/// @throws ConfigError (the configuration's file, the key's pointer) naming every place tried.
std::filesystem::path config_path(const Config& config, const std::string& key, const std::string& fallback);
/// The same for a required key.
std::filesystem::path config_path(const Config& config, const std::string& key);

}  // namespace rigger
