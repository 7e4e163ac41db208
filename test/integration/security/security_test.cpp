// DDS Security with real processes (docs/security.md): a PKI made by deploy/security/make-pki
// into the test's folder; a small secured cell (task controller + a scripted executor) brought up by
// `rigger-compose up --secure`; three intruders — no identity, a valid identity without permission for
// the recipe topic, and a valid identity whose permissions were signed by the identity CA — each try to
// CANCEL the running task, submit a recipe and command a crane velocity while a permitted riggerctl runs
// a recipe. The cell must accept none of it: the task SUCCEEDS, no intruder task gets a status, and the
// test's own permitted reader of rigger/crane/cmd_velocity receives only the permitted control's command.
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <memory>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "../two_step_recipe.hpp"
#include "rigger/dds/pubsub.hpp"
#include "rigger/dds/qos.hpp"
#include "rigger/protocol/crane.hpp"
#include "rigger/protocol/task.hpp"
#include "rigger/testing/cell.hpp"
#include "security_support.hpp"

namespace rigger::testing {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;
using namespace security;
using namespace std::chrono_literals;

TestPki g_pki;
std::string g_base;

class SecurityTest : public ::testing::Test {
 public:
  static void SetUpTestSuite() {
    g_base = std::string(RIGGER_BINARY_DIR) + "/test-logs/SecurityTest-" + std::to_string(getpid());
    g_pki.make(g_base, "rigger-security-test");
    // The test's own participant (the Cell's) is a permitted reader of everything: identity "observer".
    g_pki.join_as("observer");
  }

  static void TearDownTestSuite() { g_pki.remove(); }

 protected:
  void SetUp() override {
    if (HasFatalFailure()) return;
    dir_ = cell_.log_dir();
    compose_ = dir_ + "/compose.yaml";
    const json tc = {{"journal_path", dir_ + "/journal.sqlite"}, {"executor_wait_s", 0.3}};
    // Each Localize takes 4 s: the task still runs when the intruders are done.
    const json exec = {{"skills", {"Localize"}},
                       {"nodes", json::object()},
                       {"behaviours", {{"Localize", {{"mode", "succeed"}, {"delay_s", 4.0}, {"progress_steps", 2}}}}}};
    write_text(dir_ + "/tc.json", tc.dump(2));
    write_text(dir_ + "/exec.json", exec.dump(2));
    std::ofstream out(compose_);
    out << "root: " << RIGGER_SOURCE_DIR << "\n"
        << "bin_dir: " << bin_dir() << "\n"
        << "dds: {domain: " << cell_.domain_id() << ", config: deploy/cyclonedds.xml}\n"
        << "log_dir: " << dir_ << "/compose\n"
        << "services:\n"
        << "  task_controller: {binary: task_controller, config: " << dir_ << "/tc.json, ready_timeout_s: 30}\n"
        << "  exec: {binary: scripted_executor, config: " << dir_
        << "/exec.json, ready_timeout_s: 30, env: {RIGGER_IDENTITY: perception-skills}}\n";
  }

  void TearDown() override {
    if (compose_up_) {
      const auto [down, out] = compose("down", {"down"});
      EXPECT_TRUE(down.ok()) << out;
    }
    if (HasFailure()) {
      std::cerr << "===== logs in " << dir_ << "\n";
      for (const auto& e : fs::recursive_directory_iterator(dir_))
        if (e.is_regular_file() && e.path().extension() == ".log")
          std::cerr << "----- " << e.path().filename().string() << "\n" << slurp(e.path().string()) << "\n";
    }
  }

  std::pair<ExitStatus, std::string> compose(const std::string& name, std::vector<std::string> args) {
    args.insert(args.begin(), {"--file", compose_});
    return run(g_base, name + "-" + std::to_string(cell_.domain_id()), own_binary("rigger-compose"), args,
               {{"RIGGER_IDENTITY", "rigger-compose"}}, 90s);
  }

  std::string service_log(const std::string& name) { return slurp(dir_ + "/compose/" + name + ".log"); }

  std::unique_ptr<ChildProcess> start(const std::string& name, const std::string& binary,
                                      const std::vector<std::string>& args,
                                      const std::map<std::string, std::string>& env) {
    dds::EventLoop* loop = &cell_.loop();
    return std::make_unique<ChildProcess>(binary, args, env, dir_ + "/" + name + ".log",
                                          [loop] { loop->post([] {}); });
  }

  std::map<std::string, std::string> secure_env(const std::string& identity) {
    return g_pki.env(identity, cell_.domain_id());
  }

  Cell cell_;
  std::string dir_, compose_;
  bool compose_up_ = false;
};

TEST_F(SecurityTest, IntrudersAreIgnoredWhileAPermittedRiggerctlRunsARecipe) {
  ASSERT_FALSE(HasFatalFailure());
  // What the test's permitted participant sees: every task status change, every crane velocity.
  std::map<std::string, std::vector<int>> task_states;
  std::vector<std::string> velocity_sources;
  dds::Reader<rigger_task_TaskStatus> statuses(cell_.participant(), protocol::task::kStatus,
                                               dds::qos::state_changes());
  dds::Reader<rigger_crane_CraneVelocityCommand> velocities(cell_.participant(), protocol::crane::kCmdVelocity);
  cell_.loop().on_data(statuses, [&] {
    statuses.take([&](const rigger_task_TaskStatus& s, const dds_sample_info_t&) {
      task_states[s.task_id].push_back(static_cast<int>(s.state));
    });
  });
  cell_.loop().on_data(velocities, [&] {
    velocities.take([&](const rigger_crane_CraneVelocityCommand& v, const dds_sample_info_t&) {
      velocity_sources.push_back(v.source);
    });
  });
  const auto has_state = [&](const std::string& task, rigger_task_TaskState s) {
    const auto it = task_states.find(task);
    return it != task_states.end() && std::count(it->second.begin(), it->second.end(), static_cast<int>(s)) > 0;
  };
  const auto finished = [&](const std::string& task) {
    return has_state(task, rigger_task_TASK_SUCCEEDED) || has_state(task, rigger_task_TASK_FAILED) ||
           has_state(task, rigger_task_TASK_CANCELED) || has_state(task, rigger_task_TASK_REJECTED);
  };

  // The secured cell, brought up by rigger-compose (identities: task_controller, perception-skills).
  const auto [up, up_out] = compose("up", {"up", "--secure"});
  compose_up_ = true;
  ASSERT_TRUE(up.ok()) << up_out;
  ASSERT_TRUE(cell_.wait_ready({"task_controller", "exec"}, 30s)) << "the observer does not see the secured cell";

  // A permitted riggerctl runs a recipe of two 4 s Localize skills.
  const std::string task = "secure-run";
  const json recipe = two_step(task);
  write_text(dir_ + "/recipe.json", recipe.dump(2));
  auto ctl = start("riggerctl", "riggerctl",
                   {"--domain", std::to_string(cell_.domain_id()), "run", dir_ + "/recipe.json", "--timeout", "60"},
                   secure_env("riggerctl"));
  ASSERT_TRUE(cell_.wait_until([&] { return has_state(task, rigger_task_TASK_RUNNING) || !ctl->running(); }, 30s));
  ASSERT_TRUE(has_state(task, rigger_task_TASK_RUNNING)) << ctl->log();

  // The intruders, and a control that may command the crane (admittance_control's identity): its
  // velocity must reach the test's reader, which shows that an accepted one would have been seen.
  std::vector<Probe> probes = intruders(g_pki, cell_.domain_id());
  probes.push_back({"control", secure_env("admittance_control"), nullptr});
  for (auto& p : probes)
    p.process =
        start("probe-" + p.label, own_binary("rigger_security_probe"), probe_args(p, cell_.domain_id(), task), p.env);
  ASSERT_TRUE(cell_.wait_until(
      [&] {
        for (auto& p : probes)
          if (p.process->running()) return false;
        return true;
      },
      60s));
  for (auto& p : probes) {
    const auto st = p.process->wait(1s);
    ASSERT_TRUE(st && st->ok()) << p.label << ": " << p.process->log();
  }
  // The CANCELs were sent while the task ran.
  ASSERT_FALSE(finished(task)) << "the task ended before the intruders were done: the test proves nothing";

  // The permitted riggerctl sees its task through.
  ASSERT_TRUE(cell_.wait_until([&] { return !ctl->running(); }, 60s));
  const auto ctl_status = ctl->wait(1s);
  ASSERT_TRUE(ctl_status);
  EXPECT_EQ(ctl_status->code, 0) << ctl->log();
  EXPECT_NE(ctl->log().find("task " + task + " SUCCEEDED"), std::string::npos) << ctl->log();
  EXPECT_TRUE(cell_.wait_until([&] { return has_state(task, rigger_task_TASK_SUCCEEDED); }, 10s));
  EXPECT_FALSE(has_state(task, rigger_task_TASK_CANCELED));

  // The control's velocity arrived (the reader works); no intruder's did; no intruder task exists.
  EXPECT_TRUE(cell_.wait_until([&] { return !velocity_sources.empty(); }, 10s)) << "the control's velocity never came";
  for (const auto& source : velocity_sources) EXPECT_EQ(source, "probe-control");
  for (const auto& label : {"no-identity", "no-permission", "rogue-permissions"})
    EXPECT_EQ(task_states.count(std::string("attack-") + label), 0u) << label << "'s recipe got a status";
  EXPECT_EQ(task_states.count("attack-control"), 0u) << "the control may not submit recipes";

  // Every attempt is in a log: the probes' own, which say what DDS did with them.
  expect_intruders_logged(dir_);
  const auto probe_log = [&](const std::string& label) { return slurp(dir_ + "/probe-" + label + ".log"); };
  // The permissions signed by the identity CA are rejected by the cell's own DDS, which logs it.
  EXPECT_NE(service_log("task_controller").find(kRoguePermissionsRejected), std::string::npos)
      << service_log("task_controller");
  EXPECT_NE(probe_log("control").find(std::string(protocol::crane::kCmdVelocity.name) + ": MATCHED"), std::string::npos)
      << probe_log("control");
  EXPECT_NE(probe_log("control").find(std::string(protocol::task::kRecipe.name) + ": writer REFUSED locally"),
            std::string::npos)
      << probe_log("control");
}

}  // namespace
}  // namespace rigger::testing
