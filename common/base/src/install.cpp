#include "rigger/base/install.hpp"

#include <system_error>

#include "rigger/base/config.hpp"

namespace rigger {

namespace fs = std::filesystem;

fs::path executable_path() {
  std::error_code ec;
  auto p = fs::read_symlink("/proc/self/exe", ec);
  return ec ? fs::path{} : p;
}

fs::path data_dir(const fs::path& executable) {
  if (executable.empty()) return {};
  return executable.parent_path().parent_path() / "share" / "rigger";
}

std::string DataPath::not_found(const fs::path& name) const {
  if (tried.empty()) return name.string() + " not found (no data folder: the running executable is unknown)";
  std::string out = name.string() + " not found (tried " + tried.front().string();
  for (std::size_t i = 1; i < tried.size(); ++i) out += ", then " + tried[i].string();
  return out + ")";
}

DataPath find_data_path(const fs::path& name, const fs::path& named_in, const fs::path& data) {
  DataPath out;
  if (name.is_absolute()) {
    out.tried.push_back(name);
  } else {
    std::error_code ec;
    if (!named_in.empty()) out.tried.push_back(fs::absolute(named_in, ec).parent_path() / name);
    if (!data.empty()) out.tried.push_back(data / name);
  }
  for (const fs::path& candidate : out.tried) {
    std::error_code ec;
    if (fs::exists(candidate, ec)) {
      out.path = candidate.lexically_normal();
      out.found = true;
      return out;
    }
  }
  if (!out.tried.empty()) out.path = out.tried.front().lexically_normal();
  return out;
}

// Config::parse() names an origin that need not be a file: only a real file has a folder to look in.
fs::path config_file_of(const Config& config) {
  std::error_code ec;
  return fs::is_regular_file(config.file(), ec) ? fs::path(config.file()) : fs::path();
}

namespace {

fs::path find_for(const Config& config, const std::string& key, const std::string& name, bool named_by_config) {
  if (name.empty()) config.fail(key, "expected a path, got an empty string");
  const DataPath found = find_data_path(name, named_by_config ? config_file_of(config) : fs::path(), data_dir());
  if (!found.found) config.fail(key, (named_by_config ? "" : "default ") + found.not_found(name));
  return found.path;
}

}  // namespace

fs::path config_path(const Config& config, const std::string& key, const std::string& fallback) {
  return config.has(key) ? find_for(config, key, config.get<std::string>(key), true)
                         : find_for(config, key, fallback, false);
}

fs::path config_path(const Config& config, const std::string& key) {
  return find_for(config, key, config.get<std::string>(key), true);
}

}  // namespace rigger
