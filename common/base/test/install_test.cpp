#include "rigger/base/install.hpp"

#include <unistd.h>

#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "rigger/base/config.hpp"

namespace rigger {
namespace {

TEST(InstallTest, DataDirIsBesideTheBinFolder) {
  EXPECT_EQ(data_dir("/opt/rigger/bin/riggerctl"), std::filesystem::path("/opt/rigger/share/rigger"));
  EXPECT_EQ(data_dir("/home/u/rigger/build/tests/x_test"), std::filesystem::path("/home/u/rigger/build/share/rigger"));
  EXPECT_TRUE(data_dir(std::filesystem::path{}).empty());
}

TEST(InstallTest, ExecutablePathIsThisTestBinary) {
  const auto exe = executable_path();
  ASSERT_FALSE(exe.empty());
  EXPECT_TRUE(exe.is_absolute());
  EXPECT_EQ(exe.filename(), "rigger_base_test");
}

// A scratch tree: <root>/data (an installation's share/rigger) and <root>/etc/rigger (a configuration
// folder outside it), with the files each test puts there.
class DataPathTest : public ::testing::Test {
 protected:
  DataPathTest() {
    char pattern[] = "/tmp/rigger-install-test-XXXXXX";
    root_ = ::mkdtemp(pattern);
    std::filesystem::create_directories(data() / "deploy" / "cell");
    std::filesystem::create_directories(etc());
  }
  ~DataPathTest() override { std::filesystem::remove_all(root_); }

  std::filesystem::path data() const { return root_ / "data"; }
  std::filesystem::path etc() const { return root_ / "etc" / "rigger"; }
  static void touch(const std::filesystem::path& p, const std::string& text = "{}") {
    std::filesystem::create_directories(p.parent_path());
    std::ofstream(p) << text;
  }

  std::filesystem::path root_;
};

TEST_F(DataPathTest, AbsolutePathIsTakenAsItIs) {
  touch(root_ / "abs.json");
  const DataPath p = find_data_path(root_ / "abs.json", etc() / "svc.json", data());
  EXPECT_TRUE(p.found);
  EXPECT_EQ(p.path, root_ / "abs.json");
  EXPECT_EQ(p.tried.size(), 1u);
}

TEST_F(DataPathTest, RelativePathIsTriedBesideItsConfigurationFirst) {
  touch(etc() / "cell.json");
  touch(data() / "cell.json");
  const DataPath p = find_data_path("cell.json", etc() / "svc.json", data());
  EXPECT_TRUE(p.found);
  EXPECT_EQ(p.path, etc() / "cell.json");
}

TEST_F(DataPathTest, RelativePathFallsBackToTheDataFolder) {
  touch(data() / "deploy" / "cell" / "simulated_cell.json");
  const DataPath p = find_data_path("deploy/cell/simulated_cell.json", etc() / "svc.json", data());
  EXPECT_TRUE(p.found);
  EXPECT_EQ(p.path, data() / "deploy" / "cell" / "simulated_cell.json");
}

TEST_F(DataPathTest, ParentFolderPathsAreNormalised) {
  touch(data() / "deploy" / "cell" / "simulated_cell.json");
  touch(data() / "deploy" / "config" / "svc.json");
  const DataPath p = find_data_path("../cell/simulated_cell.json", data() / "deploy" / "config" / "svc.json", data());
  EXPECT_TRUE(p.found);
  EXPECT_EQ(p.path, data() / "deploy" / "cell" / "simulated_cell.json");
}

// A default is the installation's, whatever the working directory holds.
TEST_F(DataPathTest, DefaultIgnoresTheWorkingDirectory) {
  touch(root_ / "deploy" / "cell" / "simulated_cell.json");
  const auto cwd = std::filesystem::current_path();
  std::filesystem::current_path(root_);
  const DataPath p = find_data_path("deploy/cell/simulated_cell.json", {}, data());
  std::filesystem::current_path(cwd);
  EXPECT_FALSE(p.found);
  ASSERT_EQ(p.tried.size(), 1u);
  EXPECT_EQ(p.tried[0], data() / "deploy" / "cell" / "simulated_cell.json");
}

TEST_F(DataPathTest, NotFoundNamesEveryPlaceTried) {
  const DataPath p = find_data_path("cell.json", etc() / "svc.json", data());
  EXPECT_FALSE(p.found);
  EXPECT_EQ(p.not_found("cell.json"), "cell.json not found (tried " + (etc() / "cell.json").string() + ", then " +
                                          (data() / "cell.json").string() + ")");
}

TEST_F(DataPathTest, ConfigPathNamesTheKeyAndThePlacesTried) {
  touch(etc() / "svc.json", R"({"cell_file": "missing.json", "models": "models"})");
  std::filesystem::create_directories(etc() / "models");
  const Config config = Config::load((etc() / "svc.json").string());
  EXPECT_EQ(config_path(config, "models"), etc() / "models");  // a folder is found like a file
  try {
    config_path(config, "cell_file");
    FAIL() << "expected a ConfigError";
  } catch (const ConfigError& e) {
    EXPECT_EQ(e.file(), (etc() / "svc.json").string());
    EXPECT_EQ(e.pointer(), "/cell_file");
    EXPECT_NE(std::string(e.what()).find((etc() / "missing.json").string()), std::string::npos) << e.what();
  }
  // An absent key: the default, in the running program's data folder (this test's build tree).
  try {
    config_path(config, "library_file", "no/such/default.json");
    FAIL() << "expected a ConfigError";
  } catch (const ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("default no/such/default.json not found (tried " +
                                         (data_dir() / "no/such/default.json").string() + ")"),
              std::string::npos)
        << e.what();
  }
}

// Every target is compiled with RIGGER_SOURCE_DIR and RIGGER_BINARY_DIR defined (for the tests, the
// benchmarks and the fuzzers), but an installed program must not reach for either tree: it finds its
// files through data_dir() or its configuration. Code outside test/, test_support/, bench/ and fuzz/ folders
// names neither.
TEST(InstallTest, NoProgramNamesTheSourceOrBuildTree) {
  namespace fs = std::filesystem;
  std::vector<std::string> offenders;
  for (const char* top : {"common", "services", "tools"}) {
    for (const auto& entry : fs::recursive_directory_iterator(fs::path(RIGGER_SOURCE_DIR) / top)) {
      if (!entry.is_regular_file()) continue;
      const auto ext = entry.path().extension();
      if (ext != ".cpp" && ext != ".hpp" && ext != ".h" && ext != ".c") continue;
      const std::string rel = fs::relative(entry.path(), RIGGER_SOURCE_DIR).string();
      if (rel.find("/test/") != std::string::npos || rel.find("/test_support/") != std::string::npos ||
          rel.find("/bench/") != std::string::npos ||
          rel.find("/fuzz/") != std::string::npos)
        continue;
      std::ifstream in(entry.path());
      const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
      for (const char* name : {"RIGGER_SOURCE_DIR", "RIGGER_BINARY_DIR"})
        if (text.find(name) != std::string::npos) offenders.push_back(rel + " (" + name + ")");
    }
  }
  EXPECT_TRUE(offenders.empty()) << ::testing::PrintToString(offenders);
}

}  // namespace
}  // namespace rigger
