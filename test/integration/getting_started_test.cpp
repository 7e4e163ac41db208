// docs/getting-started.md step 2, done as written in a plain shell: no CYCLONEDDS_URI in the
// environment. `deploy/rigger-compose up` starts the cell (the compose file gives its services
// deploy/cyclonedds.xml); riggerctl, started by hand, must find the same configuration on its own (the
// installation's copy next to its bin/, rigger/dds/configuration.hpp), list every service and run the
// scenario. The only departures from the page: RIGGER_DOMAIN is the test's private domain (so the test
// does not meet a cell someone else runs), riggerctl is the build's bin/, wherever the build is, and the
// run takes a fresh --task-id (the journal refuses a task id it has seen, and it outlives the test).
// Like the demo it uses the compose file's PLC port (1502): RUN_SERIAL.
#include <chrono>
#include <ctime>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "shell_support.hpp"

namespace rigger::testing {
namespace {

using namespace std::chrono_literals;

class GettingStartedTest : public ShellTest {
 protected:
  void TearDown() override {
    if (up_) {
      const auto r = sh("down", "deploy/rigger-compose down", 60s);
      EXPECT_TRUE(r.status.ok()) << r.output;
    }
    ShellTest::TearDown();
  }

  /// Runs `command` with bash in the source tree, with CYCLONEDDS_URI removed from its environment.
  ShellResult sh(const std::string& name, const std::string& command, std::chrono::milliseconds timeout) {
    return bash(name, "cd '" RIGGER_SOURCE_DIR "' && exec " + plain_env() + " RIGGER_BUILD_DIR='" + build_dir() + "' " +
                          command,
                timeout);
  }

  static std::string build_dir() { return bin_dir() + "/.."; }
  static std::string riggerctl() { return bin_dir() + "/riggerctl"; }

  bool up_ = false;
};

TEST_F(GettingStartedTest, Step2WithoutCycloneddsUri) {
  auto r = sh("up", "deploy/rigger-compose up", 240s);
  up_ = true;
  ASSERT_TRUE(r.status.ok()) << r.output << compose_logs();

  r = sh("services", riggerctl() + " services", 30s);
  ASSERT_TRUE(r.status.ok()) << r.output;
  for (const char* id :
       {"cell_sim", "crane_gateway", "world_model", "vision_tracker", "admittance_control", "monitor_host",
        "robot-skills", "perception-skills", "operator-skills", "task_controller", "scripted_operator"}) {
    EXPECT_NE(r.output.find(std::string("\n") + id + " "), std::string::npos) << id << " missing:\n" << r.output;
  }
  EXPECT_EQ(r.output.find("LOST"), std::string::npos) << r.output;

  r = sh("skills", riggerctl() + " skills", 30s);
  EXPECT_TRUE(r.status.ok()) << r.output;
  EXPECT_NE(r.output.find("InsertVisuallyGuided"), std::string::npos) << r.output;

  // A task id is used once (the journal, /var/tmp/rigger/…, keeps every task): a new one per run.
  const std::string task_id =
      "getting-started-" + std::to_string(cell_.domain_id()) + "-" + std::to_string(::time(nullptr));
  r = sh("run", riggerctl() + " run recipes/crane_insert.json --task-id " + task_id, 300s);
  EXPECT_TRUE(r.status.ok()) << r.output;
  EXPECT_NE(r.output.find("SUCCEEDED"), std::string::npos) << r.output;

  r = sh("down", "deploy/rigger-compose down", 60s);
  up_ = !r.status.ok();
  EXPECT_TRUE(r.status.ok()) << r.output;
}

// The other half of the rule: a tool that finds nobody names the domain and the configuration it used.
TEST_F(GettingStartedTest, NobodyThereSaysWhichDomainAndConfiguration) {
  const auto r = sh("status", riggerctl() + " status --timeout 1", 30s);
  EXPECT_EQ(r.status.code, 3) << r.output;
  EXPECT_NE(r.output.find("no task controller on domain " + std::to_string(cell_.domain_id()) +
                          " (DDS configuration file://"),
            std::string::npos)
      << r.output;
  EXPECT_NE(r.output.find("/share/rigger/cyclonedds.xml from the installation)"), std::string::npos) << r.output;
}

}  // namespace
}  // namespace rigger::testing
