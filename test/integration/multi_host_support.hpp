#pragma once
// The cell spread over three hosts (docs/deploy.md): Linux network namespaces made by deploy/lab-hosts, joined
// by veth pairs and a bridge, each running its share of deploy/compose.lab.yaml with rigger-compose and
// the shipped lab DDS configuration (multicast discovery on eth0). Nothing is faked: real binaries, real
// DDS across the namespaces' interfaces, and a link cut by taking a host's port on the bridge down.
//
//   devices     cell_sim (robot, crane + PLC emulator, camera), crane_gateway, vision_tracker, admittance,
//               monitor_host
//   skills      world_model, cad, the three skill executors
//   controller  task_controller, scripted_operator, console; riggerctl runs here, as the operator's
//
// The test process itself watches from the devices host: its main thread enters that namespace before
// it makes its DDS participant, so its threads and sockets live there too.
//
// Needs root (network namespaces); skipped, saying so, without it. Each test has its own lab (named
// after the test's PID), so these tests need no DDS domain or port of their own beyond the lease.
#include <fcntl.h>
#include <sched.h>
#include <signal.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <optional>
#include <ctime>
#include <map>
#include <memory>
#include <set>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "scenario_support.hpp"
#include "rigger/testing/require.hpp"

namespace rigger::testing::scenario {

inline const std::vector<std::string> kHosts = {"devices", "skills", "controller"};
inline const std::vector<std::string> kServices = {
    "cell_sim",     "crane_gateway",   "vision_tracker",    "admittance_control", "world_model",      "cad",
    "monitor_host", "robot-skills",    "perception-skills", "operator-skills",    "task_controller",  "scripted_operator",
    "console"};

struct ShellResult {
  ExitStatus status;
  std::string output;
};

class MultiHostTest : public ::testing::Test {
 protected:
  void SetUp() override {
    RIGGER_REQUIRE_OR_SKIP(geteuid() == 0, "network namespaces need root (CAP_NET_ADMIN): not run");
    lab_ = "m" + std::to_string(getpid() % 10000000);
    const auto made = lab("up", {"devices", "skills", "controller"});
    ASSERT_TRUE(made.status.ok()) << "deploy/lab-hosts up failed:\n" << made.output;
    lab_made_ = true;
    // Watch from the devices host: enter its namespace before any DDS entity of this process exists.
    root_ns_ = open("/proc/self/ns/net", O_RDONLY | O_CLOEXEC);
    const int devices = open(("/var/run/netns/" + lab_ + "-devices").c_str(), O_RDONLY | O_CLOEXEC);
    ASSERT_GE(devices, 0);
    ASSERT_EQ(setns(devices, CLONE_NEWNET), 0) << strerror(errno);
    close(devices);
    setenv("CYCLONEDDS_URI", dds_config().c_str(), 1);
    cell_ = std::make_unique<Cell>();
  }

  void TearDown() override {
    // Controller first, so that no task runs while the devices go away (docs/deploy.md).
    for (auto it = kHosts.rbegin(); it != kHosts.rend() && !up_.empty(); ++it) {
      if (!up_.count(*it)) continue;
      const auto r = on(*it, "down-" + *it, compose() + " down", 60s);
      EXPECT_TRUE(r.status.ok()) << "rigger-compose down on " << *it << ":\n" << r.output;
    }
    if (HasFailure() && cell_) std::printf("logs in %s\n", cell_->log_dir().c_str());
    cell_.reset();
    if (root_ns_ >= 0) {
      EXPECT_EQ(setns(root_ns_, CLONE_NEWNET), 0);
      close(root_ns_);
    }
    if (lab_made_) {
      EXPECT_TRUE(lab("down", {}).status.ok());
    }
  }

  static std::string dds_config() { return "file://" RIGGER_SOURCE_DIR "/deploy/cyclonedds-lab.xml"; }
  std::string compose() const { return bin_dir() + "/rigger-compose --file deploy/compose.lab.yaml"; }
  std::string riggerctl() const { return bin_dir() + "/riggerctl --domain " + std::to_string(cell_->domain_id()); }

  /// `deploy/lab-hosts VERB ARGS…` for this test's lab.
  ShellResult lab(const std::string& verb, const std::vector<std::string>& args) {
    std::string command = "deploy/lab-hosts " + verb;
    for (const auto& a : args) command += " " + a;
    return shell("lab-" + verb, command, 60s);
  }

  /// Runs `command` with bash in the source tree on lab host `host`, as that host's own shell would:
  /// its name, the test's domain, the lab's DDS configuration, logs under the test's log folder.
  ShellResult on(const std::string& host, const std::string& name, const std::string& command,
                 std::chrono::milliseconds timeout) {
    return shell(name, "deploy/lab-hosts exec " + host + " env " + host_env(host) + " " + command, timeout);
  }
  std::unique_ptr<ChildProcess> start_on(const std::string& host, const std::string& name, const std::string& command) {
    return start("deploy/lab-hosts exec " + host + " env " + host_env(host) + " " + command, name);
  }
  std::string host_env(const std::string& host) const {
    // Each host keeps its state (world model database, controller journal) in a folder of its own, as
    // separate machines would: not in /var/tmp/rigger, which other tests' cells running at the same time
    // use too (a world model waiting on another's lock there took 13 s to come up).
    return "RIGGER_HOST=" + host + " RIGGER_DOMAIN=" + std::to_string(cell_->domain_id()) + " RIGGER_LOG_ROOT='" +
           cell_->log_dir() + "' RIGGER_STATE_DIR='" + cell_->log_dir() + "/state-" + host + "' RIGGER_BUILD_DIR='" +
           bin_dir() + "/..' CYCLONEDDS_URI=" + dds_config();
  }

  std::unique_ptr<ChildProcess> start(const std::string& command, const std::string& name) {
    const std::string dir = cell_ ? cell_->log_dir() : "/tmp";
    return std::make_unique<ChildProcess>("/bin/bash", std::vector<std::string>{"-c", "cd '" RIGGER_SOURCE_DIR "' && " + command},
                                          std::map<std::string, std::string>{{"RIGGER_LAB", lab_}},
                                          dir + "/" + lab_ + "-" + name + ".out");
  }
  ShellResult shell(const std::string& name, const std::string& command, std::chrono::milliseconds timeout) {
    auto p = start(command, name);
    return finish(*p, command, timeout);
  }
  static ShellResult finish(ChildProcess& p, const std::string& what, std::chrono::milliseconds timeout) {
    auto st = p.wait(timeout);
    if (!st) {
      p.signal(SIGKILL);
      st = p.wait(5s);
      ADD_FAILURE() << what << " did not finish within " << timeout.count() << " ms\n" << p.log();
    }
    return {st.value_or(ExitStatus{}), p.log()};
  }

  /// `rigger-compose up` on the three hosts at once (each waits on DDS for what it needs from the others).
  bool up_all() {
    std::map<std::string, std::unique_ptr<ChildProcess>> ups;
    for (const auto& h : kHosts) ups[h] = start_on(h, "up-" + h, compose() + " up");
    bool ok = true;
    for (auto& [h, p] : ups) {
      const auto r = finish(*p, "up on " + h, 240s);
      up_.insert(h);
      if (!r.status.ok()) {
        ADD_FAILURE() << "rigger-compose up on " << h << ": " << r.status.describe() << "\n" << r.output;
        ok = false;
      }
    }
    return ok;
  }

  /// A fresh task id: the journal keeps every task it has seen.
  static std::string task_id(const std::string& what) {
    return "multihost-" + what + "-" + std::to_string(std::time(nullptr)) + "-" + std::to_string(getpid());
  }

  std::string lab_;
  bool lab_made_ = false;
  int root_ns_ = -1;
  std::unique_ptr<Cell> cell_;
  std::set<std::string> up_;
};

}  // namespace rigger::testing::scenario
