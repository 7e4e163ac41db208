// `cmake --install` gives a working, relocatable tree. The build is installed into <tmp>/a,
// the folder is moved to <tmp>/b, and the README's main command, `rigger-compose demo`, is run from
// <tmp>/b alone: from / as working directory, in a plain user's environment (no CYCLONEDDS_URI) on the
// test's private DDS domain, inside a private mount namespace (`unshare --mount`) in which empty tmpfs
// mounts hide the source tree and the build tree. A binary that still reached for either tree would miss
// its file there and the demo would fail. unshare needs root (CAP_SYS_ADMIN), which the test machines
// have; without it the test skips and says so, since nothing else hides the trees from the processes
// without also hiding them from ctest. It installs what the last build made: run it after a full build,
// as test/run does. Like the demo it uses the compose file's PLC and console ports: RUN_SERIAL. The shipped
// site tools are tried from the moved installation too (make-pki).
#include <stdlib.h>

#include <chrono>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <regex>
#include <sstream>
#include <string>

#include <gtest/gtest.h>

#include "rigger/testing/process.hpp"
#include "rigger/testing/require.hpp"
#include "shell_support.hpp"

namespace rigger::testing {
namespace {

using namespace std::chrono_literals;
namespace fs = std::filesystem;

class RelocatableInstallTest : public ShellTest {
 protected:
  void SetUp() override {
    char pattern[] = "/tmp/rigger-install-test-XXXXXX";
    ASSERT_NE(::mkdtemp(pattern), nullptr);
    tmp_ = pattern;
  }

  void TearDown() override {
    if (cell_may_run_) {  // a demo that did not end cleanly may have left its supervisor and services
      const std::string down =
          "exec " + plain_env(state_dir()) + " " + shell_quoted(prefix() + "/bin/rigger-compose") + " down";
      const auto r = bash("down", down, 60s);
      EXPECT_TRUE(r.status.ok()) << r.output;
    }
    std::error_code ec;
    fs::remove_all(tmp_, ec);
    ShellTest::TearDown();
  }

  std::string prefix() const { return tmp_ + "/b"; }
  /// The demo's state folder: outside the build tree, which with_trees_hidden() hides.
  std::string state_dir() const { return tmp_ + "/state"; }
  static std::string build_dir() { return fs::canonical(bin_dir() + "/..").string(); }
  static std::string source_dir() { return fs::canonical(RIGGER_SOURCE_DIR).string(); }

  /// A script that runs `command` from / in a private mount namespace where the build tree and the source
  /// tree are empty folders; it exits 99 if they are still visible.
  std::string with_trees_hidden(const std::string& command) const {
    const std::string build = shell_quoted(build_dir()), source = shell_quoted(source_dir());
    const std::string inner = "mount -t tmpfs -o size=1m rigger-hidden " + build +
                              " && mount -t tmpfs -o size=1m rigger-hidden " + source +
                              " && if [ -e " + build + "/CMakeCache.txt ] || [ -e " + source +
                              "/CMakeLists.txt ]; then echo 'source or build tree still visible'; exit 99; fi" +
                              " && cd / && exec " + plain_env(state_dir()) + " " + command;
    return "exec unshare --mount /bin/bash -c \"" + inner + "\"";
  }

  std::string tmp_;
  bool cell_may_run_ = false;
};

TEST_F(RelocatableInstallTest, MovedInstallationRunsTheDemoWithoutSourceOrBuildTree) {
  RIGGER_REQUIRE_OR_SKIP(bash("probe", "exec unshare --mount true", 10s).status.ok(),
                         "unshare --mount is not permitted here (needs root): the source and build trees cannot be hidden");

  const auto t0 = std::chrono::steady_clock::now();
  auto r = bash("install",
                shell_quoted(RIGGER_CMAKE_COMMAND) + " --install " + shell_quoted(build_dir()) + " --prefix " +
                    shell_quoted(tmp_ + "/a"),
                120s);
  ASSERT_TRUE(r.status.ok()) << r.output;
  const double install_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  std::uintmax_t bytes = 0, files = 0;
  for (const auto& entry : fs::recursive_directory_iterator(tmp_ + "/a")) {
    if (!entry.is_regular_file()) continue;
    bytes += entry.file_size();
    ++files;
  }
  std::printf("installed %ju files, %.1f MiB, in %.1f s\n", files, static_cast<double>(bytes) / (1 << 20), install_s);
  RecordProperty("install_bytes", std::to_string(bytes));
  fs::rename(tmp_ + "/a", prefix());

  // Every file the console's import map names was installed (the pages load three.js and uPlot from it).
  std::ifstream index(prefix() + "/share/rigger/web/index.html");
  ASSERT_TRUE(index) << "no share/rigger/web/index.html in the installation";
  std::stringstream html;
  html << index.rdbuf();
  const std::string text = html.str();
  const std::regex module_path(R"re("(/node_modules/[^"]+)")re");
  int named = 0;
  for (std::sregex_iterator it(text.begin(), text.end(), module_path), end; it != end; ++it, ++named) {
    EXPECT_TRUE(fs::exists(prefix() + "/share/rigger/web" + (*it)[1].str())) << (*it)[1].str() << " not installed";
  }
  EXPECT_GE(named, 3) << text;

  // The installation describes itself: its own data folder and bin/, no path of the trees.
  r = bash("config", with_trees_hidden(shell_quoted(prefix() + "/bin/rigger-compose") + " config"), 30s);
  ASSERT_TRUE(r.status.ok()) << r.output;
  EXPECT_NE(r.output.find("root     " + prefix() + "/share/rigger\n"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("bin_dir  " + prefix() + "/bin\n"), std::string::npos) << r.output;
  EXPECT_EQ(r.output.find("(not built)"), std::string::npos) << "a service binary was not installed:\n" << r.output;

  // The site tools are shipped and work from the installation: make-pki reads the installed catalog's
  // access table and signs a permissions document for every role, the ROS 2 driver's from the shipped grants.
  const std::string security = prefix() + "/share/rigger/deploy/security";
  r = bash("make-pki",
           with_trees_hidden(shell_quoted(security + "/make-pki") + " --extra " +
                             shell_quoted(security + "/ros2.grants") + " " + shell_quoted(tmp_ + "/pki")),
           120s);
  ASSERT_TRUE(r.status.ok()) << r.output;
  for (const char* identity : {"task_controller", "console", "ros2_bridge", "ros2_driver"})
    EXPECT_TRUE(fs::exists(tmp_ + "/pki/identities/" + identity + "/permissions.p7s")) << identity << "\n" << r.output;
  EXPECT_TRUE(fs::exists(prefix() + "/share/rigger/deploy/lab-hosts"));

  cell_may_run_ = true;
  const auto t1 = std::chrono::steady_clock::now();
  r = bash("demo", with_trees_hidden(shell_quoted(prefix() + "/bin/rigger-compose") + " demo"), 420s);
  std::printf("demo from the moved installation: %.1f s\n",
              std::chrono::duration<double>(std::chrono::steady_clock::now() - t1).count());
  ASSERT_TRUE(r.status.ok()) << r.status.describe() << "\n" << r.output << compose_logs();
  cell_may_run_ = false;
  EXPECT_NE(r.output.find("SUCCEEDED"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("rigger-compose demo: riggerctl succeeded"), std::string::npos) << r.output;
}

}  // namespace
}  // namespace rigger::testing
