// The paper's crane scenario with DDS Security on (docs/security.md): every service of the
// simulated cell (scenario_support.hpp) on deploy/cyclonedds-secure.xml with its own identity and
// permissions from a PKI that deploy/security/make-pki makes for this test, as `rigger-compose up --secure`
// runs them; a permitted riggerctl runs recipes/crane_insert.json. While the robot carries the load, three
// intruders — no identity, a valid identity without permission for the recipe topic, and a valid identity
// whose permissions were signed by the identity CA — each CANCEL that task, submit a recipe of their own
// and command a crane velocity. The task must SUCCEED as the unsecured scenario does (screwed on within
// 5 mm and 1 degree, every skill run once), the cell must accept none of the intruders' samples, and each
// attempt must be in the logs.
#include <unistd.h>

#include <algorithm>
#include <map>
#include <set>
#include <string>
#include <vector>

#include "../scenario_support.hpp"
#include "security_support.hpp"

namespace rigger::testing::scenario {
namespace {

using namespace security;

constexpr auto kTaskTimeout = std::chrono::minutes(4);
const std::string kTask = "crane-insert";  // recipes/crane_insert.json's task id

TestPki g_pki;

class SecureScenarioTest : public MultiProcessTest {
 public:
  static void SetUpTestSuite() {
    g_pki.make(std::string(RIGGER_BINARY_DIR) + "/test-logs/SecureScenarioTest-" + std::to_string(getpid()),
               "rigger-secure-scenario-test");
    // The test's own participant (the Cell's, made with the fixture) only reads: identity "observer".
    g_pki.join_as("observer");
  }
  static void TearDownTestSuite() { g_pki.remove(); }
};

TEST_F(SecureScenarioTest, CraneInsertSucceedsSecuredAndIntrudersMoveNothing) {
  ASSERT_FALSE(HasFatalFailure()) << "no PKI";
  // What the observer sees of every task and of every crane velocity command.
  std::map<std::string, std::set<int>> task_states;
  std::map<std::string, int> velocity_sources;
  dds::Reader<rigger_task_TaskStatus> statuses(cell_.participant(), protocol::task::kStatus, dds::qos::state_changes());
  dds::Reader<rigger_crane_CraneVelocityCommand> velocities(cell_.participant(), protocol::crane::kCmdVelocity);
  cell_.loop().on_data(statuses, [&] {
    statuses.take([&](const rigger_task_TaskStatus& s, const dds_sample_info_t&) {
      task_states[dds::to_string(s.task_id)].insert(static_cast<int>(s.state));
    });
  });
  cell_.loop().on_data(velocities, [&] {
    velocities.take([&](const rigger_crane_CraneVelocityCommand& v, const dds_sample_info_t&) {
      ++velocity_sources[dds::to_string(v.source)];
    });
  });

  const auto s = ScenarioCell::secured(cell_, g_pki.pki());
  ASSERT_TRUE(s->ready()) << "not every secured service came up";

  // A permitted riggerctl (identity riggerctl) runs the scenario's recipe.
  s->watch(kTask);
  ChildProcess& ctl = cell_.start("riggerctl", "riggerctl",
                                  {"--domain", std::to_string(cell_.domain_id()), "run",
                                   repo_file("recipes/crane_insert.json"), "--timeout", "300"},
                                  false, g_pki.env("riggerctl", cell_.domain_id()));

  // Once the magnet holds the load, the intruders try, one process each, all at once.
  ASSERT_TRUE(cell_.wait_until([&] { return s->gripper_holding() || task_terminal(s->task_state()); }, kTaskTimeout))
      << s->task_summary();
  ASSERT_FALSE(task_terminal(s->task_state())) << s->task_summary();
  std::vector<Probe> probes = intruders(g_pki, cell_.domain_id());
  for (auto& p : probes)
    cell_.start("probe-" + p.label, security::own_binary("rigger_security_probe"),
                probe_args(p, cell_.domain_id(), kTask), false, p.env);
  ASSERT_TRUE(cell_.wait_until(
      [&] {
        return std::none_of(probes.begin(), probes.end(),
                            [&](const Probe& p) { return cell_.process("probe-" + p.label).running(); });
      },
      60s));
  for (const auto& p : probes) {
    const auto st = cell_.process("probe-" + p.label).wait(1s);
    ASSERT_TRUE(st && st->ok()) << p.label << ": " << cell_.process("probe-" + p.label).log();
  }
  // The CANCELs went out while the load was carried.
  ASSERT_FALSE(task_terminal(s->task_state()))
      << "the task ended before the intruders were done: " << s->task_summary();
  ASSERT_TRUE(s->gripper_holding()) << "the load was dropped while the intruders tried";

  // The task goes on to its end as the unsecured scenario's does.
  ASSERT_TRUE(s->wait_task_end(kTaskTimeout)) << "the task did not end in time: " << s->task_summary();
  print_report(*s, "crane insert, secured, with intruders");
  ASSERT_EQ(s->task_state(), rigger_task_TASK_SUCCEEDED) << s->task_summary();
  expect_screwed_on(*s);
  EXPECT_FALSE(s->gripper_energized()) << "the robot should have let go at the end";
  for (const char* name :
       {"attach robot to load", "insert visually guided", "operator screws", "release and retreat"}) {
    const NodeView* n = s->node(name);
    ASSERT_NE(n, nullptr) << name;
    EXPECT_EQ(n->state, rigger_task_NODE_SUCCESS) << name;
    EXPECT_EQ(n->runs, 1) << name;
  }
  EXPECT_EQ(s->node("back off"), nullptr) << "the recovery branch ran";
  ASSERT_TRUE(cell_.wait_until([&] { return !ctl.running(); }, 30s));
  EXPECT_EQ(ctl.wait(1s).value_or(ExitStatus{}).code, 0) << ctl.log();
  EXPECT_NE(ctl.log().find("task " + kTask + " SUCCEEDED"), std::string::npos) << ctl.log();

  // Nothing of the intruders was taken: the task never CANCELED, no task of theirs got a status, and the
  // crane was commanded by admittance control alone (the observer reads rigger/crane/cmd_velocity with
  // the permissions the crane gateway's reader has; the probe's velocity names its sender).
  EXPECT_EQ(task_states[kTask].count(rigger_task_TASK_CANCELED), 0u);
  for (const auto& p : probes)
    EXPECT_EQ(task_states.count("attack-" + p.label), 0u) << p.label << "'s recipe got a status";
  EXPECT_GT(velocity_sources["admittance_control"], 0) << "the observer saw no crane velocity: it proves nothing";
  for (const auto& [source, n] : velocity_sources)
    EXPECT_EQ(source, "admittance_control") << n << " crane velocities from " << source;

  // Every attempt is in a log: the intruders' own (what DDS did with each writer), and the cell's
  // services' for the rogue permissions, which each of them rejected.
  expect_intruders_logged(cell_.log_dir());
  for (const char* service : {"task_controller", "crane_gateway", "admittance_control"}) {
    const std::string log = cell_.process(service).log();
    EXPECT_NE(log.find(kRoguePermissionsRejected), std::string::npos) << service << " did not log the rogue\n" << log;
  }
}

}  // namespace
}  // namespace rigger::testing::scenario
