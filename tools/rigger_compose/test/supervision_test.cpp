#include "rigger/compose/supervision.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <signal.h>

#include <deque>
#include <filesystem>

namespace rigger::compose {
namespace {

using std::chrono::milliseconds;
using ::testing::ElementsAre;
using ::testing::HasSubstr;
using ::testing::IsEmpty;
using Kind = SupervisionCommand::Kind;

ServiceDef def(const std::string& name, std::vector<std::string> deps = {},
               RestartPolicy policy = RestartPolicy::kAlways, const std::string& host = "localhost") {
  ServiceDef d;
  d.name = name;
  d.binary = "/bin/" + name;
  d.depends_on = std::move(deps);
  d.restart = policy;
  d.host = host;
  d.ready_timeout = milliseconds(10000);
  d.stop_timeout = milliseconds(5000);
  return d;
}

ExitInfo exit_code(int code) {
  ExitInfo e;
  e.exited = true;
  e.code = code;
  return e;
}

ExitInfo killed(int sig) {
  ExitInfo e;
  e.signal = sig;
  return e;
}

// Drives a Supervision like the supervisor process does, with a fake clock and fake PIDs: every spawn
// command is answered with the next PID at once.
class SupervisionTest : public ::testing::Test {
 protected:
  void make(std::deque<ServiceDef> defs, std::vector<bool> local = {}) {
    defs_ = std::move(defs);
    std::vector<Supervision::Entry> plan;
    for (std::size_t i = 0; i < defs_.size(); ++i) plan.push_back({&defs_[i], local.empty() || local[i]});
    sup_ = std::make_unique<Supervision>(plan);
  }
  void begin() {
    sup_->begin(now_);
    drain();
  }
  // Executes the pending commands: spawns get PIDs (recorded), signals and reports are recorded.
  void drain() {
    for (auto cmds = sup_->take_commands(); !cmds.empty(); cmds = sup_->take_commands()) {
      for (const auto& c : cmds) {
        if (c.kind == Kind::kSpawn) {
          spawned_.push_back(c.service);
          const int pid = next_pid_++;
          pids_[c.service] = pid;
          sup_->spawned(c.service, pid, now_);
        } else if (c.kind == Kind::kSignal) {
          signals_.push_back(c.service + ":" + (c.signal == SIGINT ? "INT" : c.signal == SIGKILL ? "KILL" : "?"));
          signal_pids_.push_back(c.pid);
        } else {
          reports_.push_back(c.text);
        }
      }
    }
  }
  void ready(const std::string& name) {
    sup_->announced_ready(name, pids_.at(name), now_);
    drain();
  }
  void end(const std::string& name, const ExitInfo& info) {
    sup_->exited(pids_.at(name), info, now_);
    drain();
  }
  void pass(milliseconds d) {
    now_ += d;
    sup_->advance(now_);
    drain();
  }
  ServiceState state(const std::string& name) const { return sup_->find(name)->state; }
  std::string all_reports() const {
    std::string out;
    for (const auto& r : reports_) out += r + "\n";
    return out;
  }
  void bring_up(const std::vector<std::string>& names) {
    begin();
    for (const auto& n : names) ready(n);
    ASSERT_EQ(sup_->phase(), Phase::kRunning) << all_reports();
  }

  std::deque<ServiceDef> defs_;  // deque: stable addresses
  std::unique_ptr<Supervision> sup_;
  Clock::time_point now_{std::chrono::seconds(100)};
  int next_pid_ = 1000;
  std::map<std::string, int> pids_;
  std::vector<std::string> spawned_;
  std::vector<std::string> signals_;
  std::vector<int> signal_pids_;
  std::vector<std::string> reports_;
};

TEST_F(SupervisionTest, StartsEachServiceOnlyWhenItsDependenciesAreReady) {
  make({def("sim"), def("world"), def("gateway", {"sim"}), def("skills", {"gateway", "world"})});
  begin();
  EXPECT_THAT(spawned_, ElementsAre("sim", "world"));  // independent services start together
  EXPECT_EQ(sup_->phase(), Phase::kStarting);
  ready("world");
  EXPECT_THAT(spawned_, ElementsAre("sim", "world"));
  ready("sim");
  EXPECT_THAT(spawned_, ElementsAre("sim", "world", "gateway"));
  ready("gateway");
  EXPECT_THAT(spawned_, ElementsAre("sim", "world", "gateway", "skills"));
  EXPECT_EQ(sup_->phase(), Phase::kStarting);
  ready("skills");
  EXPECT_EQ(sup_->phase(), Phase::kRunning);
  EXPECT_THAT(all_reports(), HasSubstr("all 4 services READY"));
  EXPECT_FALSE(sup_->failed());
  EXPECT_FALSE(sup_->next_deadline());
}

TEST_F(SupervisionTest, OnlyTheCurrentInstancesReadyCounts) {
  make({def("a")});
  begin();
  sup_->announced_ready("a", 999, now_);  // some other process with the same id (an earlier instance)
  drain();
  EXPECT_EQ(state("a"), ServiceState::kStarting);
  ready("a");
  EXPECT_EQ(state("a"), ServiceState::kReady);
}

TEST_F(SupervisionTest, ExitBeforeReadyFailsTheBringUpAndStopsTheRest) {
  make({def("sim"), def("world"), def("gateway", {"sim"})});
  begin();
  ready("world");
  end("sim", exit_code(2));
  EXPECT_TRUE(sup_->failed());
  EXPECT_THAT(sup_->failure(), HasSubstr("service sim ended (exit code 2)"));
  EXPECT_THAT(sup_->failure(), HasSubstr("before it announced READY"));
  EXPECT_EQ(state("gateway"), ServiceState::kStopped);  // never started
  EXPECT_THAT(spawned_, ElementsAre("sim", "world"));
  EXPECT_THAT(signals_, ElementsAre("world:INT"));
  EXPECT_EQ(sup_->phase(), Phase::kStopping);
  end("world", exit_code(0));
  EXPECT_EQ(sup_->phase(), Phase::kDone);
}

TEST_F(SupervisionTest, ReadyTimeoutFailsTheBringUp) {
  make({def("a"), def("b")});
  begin();
  ready("b");
  pass(milliseconds(9999));
  EXPECT_FALSE(sup_->failed());
  pass(milliseconds(1));
  EXPECT_TRUE(sup_->failed());
  EXPECT_THAT(sup_->failure(), HasSubstr("a did not announce READY within 10.0 s"));
  EXPECT_THAT(signals_, ElementsAre("a:INT", "b:INT"));
}

TEST_F(SupervisionTest, SpawnFailureDuringBringUpFails) {
  make({def("a"), def("b", {"a"})});
  sup_->begin(now_);
  auto cmds = sup_->take_commands();
  ASSERT_EQ(cmds.size(), 1u);
  sup_->spawn_failed("a", "/bin/a: No such file or directory", now_);
  drain();
  EXPECT_TRUE(sup_->failed());
  EXPECT_THAT(sup_->failure(), HasSubstr("could not start: /bin/a: No such file"));
  EXPECT_EQ(sup_->phase(), Phase::kDone);
  EXPECT_EQ(state("a"), ServiceState::kFailed);
  EXPECT_EQ(state("b"), ServiceState::kStopped);
}

TEST_F(SupervisionTest, CrashAfterReadyRestartsWithDoublingBackoff) {
  make({def("a")});
  bring_up({"a"});
  const int first_pid = pids_["a"];
  end("a", killed(SIGKILL));
  EXPECT_EQ(state("a"), ServiceState::kBackoff);
  EXPECT_THAT(all_reports(), HasSubstr("a ended (killed by SIGKILL)"));
  EXPECT_THAT(all_reports(), HasSubstr("restart #1 in 0.5 s"));
  ASSERT_TRUE(sup_->next_deadline());
  EXPECT_EQ(*sup_->next_deadline(), now_ + milliseconds(500));
  pass(milliseconds(499));
  EXPECT_EQ(spawned_.size(), 1u);
  pass(milliseconds(1));
  EXPECT_EQ(spawned_.size(), 2u);
  EXPECT_EQ(sup_->find("a")->restarts, 1);
  EXPECT_NE(pids_["a"], first_pid);
  ready("a");
  EXPECT_EQ(state("a"), ServiceState::kReady);

  // Crashing again soon doubles the delay; 1 s, then 2 s.
  pass(milliseconds(1000));
  end("a", exit_code(1));
  EXPECT_EQ(*sup_->next_deadline(), now_ + milliseconds(1000));
  pass(milliseconds(1000));
  ready("a");
  end("a", exit_code(1));
  EXPECT_EQ(*sup_->next_deadline(), now_ + milliseconds(2000));
  pass(milliseconds(2000));
  EXPECT_EQ(sup_->find("a")->restarts, 3);

  // An instance that stays up 30 s resets the backoff.
  ready("a");
  pass(milliseconds(30000));
  end("a", exit_code(1));
  EXPECT_EQ(*sup_->next_deadline(), now_ + milliseconds(500));
}

TEST_F(SupervisionTest, RestartPolicies) {
  make({def("always", {}, RestartPolicy::kAlways), def("onfail", {}, RestartPolicy::kOnFailure),
        def("onfail2", {}, RestartPolicy::kOnFailure), def("never", {}, RestartPolicy::kNo)});
  bring_up({"always", "onfail", "onfail2", "never"});
  end("always", exit_code(0));
  end("onfail", exit_code(0));
  end("onfail2", killed(SIGSEGV));
  end("never", killed(SIGSEGV));
  EXPECT_EQ(state("always"), ServiceState::kBackoff);
  EXPECT_EQ(state("onfail"), ServiceState::kExited);
  EXPECT_EQ(state("onfail2"), ServiceState::kBackoff);
  EXPECT_EQ(state("never"), ServiceState::kExited);
  EXPECT_THAT(all_reports(), HasSubstr("restart policy 'no': not restarted"));
  EXPECT_EQ(sup_->phase(), Phase::kRunning);
}

TEST_F(SupervisionTest, ServiceThatEndsForGoodDuringBringUpFailsIt) {
  make({def("a", {}, RestartPolicy::kNo), def("b", {"a"})});
  begin();
  ready("a");
  end("a", exit_code(0));
  EXPECT_TRUE(sup_->failed());
  EXPECT_THAT(sup_->failure(), HasSubstr("not restarted"));
}

TEST_F(SupervisionTest, StopsInReverseDependencyOrderAndKillsAfterTheTimeout) {
  make({def("sim"), def("gateway", {"sim"}), def("skills", {"gateway"}), def("monitor")});
  bring_up({"sim", "monitor", "gateway", "skills"});
  sup_->stop("signal Terminated", now_);
  drain();
  EXPECT_EQ(sup_->phase(), Phase::kStopping);
  EXPECT_THAT(signals_, ElementsAre("skills:INT", "monitor:INT"));  // the leaves first
  end("skills", exit_code(0));
  EXPECT_THAT(signals_, ElementsAre("skills:INT", "monitor:INT", "gateway:INT"));
  end("monitor", exit_code(0));
  pass(milliseconds(5000));  // gateway ignores SIGINT
  EXPECT_THAT(signals_, ElementsAre("skills:INT", "monitor:INT", "gateway:INT", "gateway:KILL"));
  EXPECT_THAT(all_reports(), HasSubstr("gateway did not stop within 5.0 s after SIGINT; SIGKILL"));
  end("gateway", killed(SIGKILL));
  EXPECT_THAT(signals_.back(), "sim:INT");
  end("sim", exit_code(0));
  EXPECT_EQ(sup_->phase(), Phase::kDone);
  EXPECT_FALSE(sup_->failed());
  for (const auto& s : sup_->services()) EXPECT_EQ(s.state, ServiceState::kStopped) << s.name();
}

TEST_F(SupervisionTest, StopCancelsBackoffAndNeverSignalsAnEndedProcess) {
  make({def("a"), def("b")});
  bring_up({"a", "b"});
  const int dead_pid = pids_["a"];
  end("a", killed(SIGKILL));
  sup_->stop("down", now_);
  drain();
  EXPECT_EQ(state("a"), ServiceState::kStopped);
  EXPECT_THAT(signals_, ElementsAre("b:INT"));
  for (int pid : signal_pids_) EXPECT_NE(pid, dead_pid);
  end("b", exit_code(0));
  EXPECT_EQ(sup_->phase(), Phase::kDone);
  pass(milliseconds(60000));
  EXPECT_EQ(spawned_.size(), 2u);  // the backoff never fired a restart
}

TEST_F(SupervisionTest, StopIsIdempotentAndUnknownPidsAreIgnored) {
  make({def("a")});
  bring_up({"a"});
  sup_->exited(424242, exit_code(0), now_);
  drain();
  EXPECT_EQ(state("a"), ServiceState::kReady);
  sup_->stop("one", now_);
  sup_->stop("two", now_);
  drain();
  EXPECT_THAT(signals_, ElementsAre("a:INT"));
}

TEST_F(SupervisionTest, RestartOnRequest) {
  make({def("a"), def("b", {"a"})});
  bring_up({"a", "b"});
  const int old_pid = pids_["a"];
  EXPECT_EQ(sup_->restart("a", now_), "");
  drain();
  EXPECT_THAT(signals_, ElementsAre("a:INT"));  // dependants keep running
  EXPECT_EQ(state("a"), ServiceState::kStopping);
  end("a", exit_code(0));
  EXPECT_EQ(state("a"), ServiceState::kStarting);
  EXPECT_NE(pids_["a"], old_pid);
  EXPECT_EQ(sup_->find("a")->restarts, 1);
  ready("a");
  EXPECT_EQ(state("a"), ServiceState::kReady);
  EXPECT_EQ(state("b"), ServiceState::kReady);
}

TEST_F(SupervisionTest, RestartOfAnExitedServiceStartsItAtOnce) {
  make({def("a", {}, RestartPolicy::kNo)});
  bring_up({"a"});
  end("a", exit_code(0));
  EXPECT_EQ(state("a"), ServiceState::kExited);
  EXPECT_EQ(sup_->restart("a", now_), "");
  drain();
  EXPECT_EQ(state("a"), ServiceState::kStarting);
  EXPECT_EQ(spawned_.size(), 2u);
}

TEST_F(SupervisionTest, RestartIsRefusedWhenItCannotApply) {
  make({def("a"), def("r", {}, RestartPolicy::kAlways, "cell-crane"), def("b", {"r"})}, {true, false, true});
  begin();
  EXPECT_THAT(sup_->restart("a", now_), HasSubstr("supervisor is starting"));
  EXPECT_THAT(sup_->restart("ghost", now_), HasSubstr("not run by this supervisor"));
  EXPECT_THAT(sup_->restart("r", now_), HasSubstr("runs on host cell-crane"));
}

TEST_F(SupervisionTest, RestartedInstanceThatIsNeverReadyIsStoppedAndRetried) {
  make({def("a")});
  bring_up({"a"});
  end("a", killed(SIGKILL));
  pass(milliseconds(500));
  ASSERT_EQ(state("a"), ServiceState::kStarting);
  pass(milliseconds(10000));
  EXPECT_THAT(all_reports(), HasSubstr("did not announce READY within 10.0 s after its restart"));
  EXPECT_EQ(state("a"), ServiceState::kStopping);
  end("a", exit_code(0));
  EXPECT_EQ(state("a"), ServiceState::kBackoff);  // counts as a failure even though it exited 0
  EXPECT_EQ(*sup_->next_deadline(), now_ + milliseconds(1000));
}

TEST_F(SupervisionTest, RemoteDependencyIsWaitedForNotStarted) {
  make({def("gateway", {}, RestartPolicy::kAlways, "cell-crane"), def("admittance", {"gateway"})}, {false, true});
  begin();
  EXPECT_THAT(spawned_, IsEmpty());
  EXPECT_EQ(state("gateway"), ServiceState::kRemote);
  sup_->announced_ready("gateway", 77, now_);  // its PID is on another host: any READY counts
  drain();
  EXPECT_THAT(spawned_, ElementsAre("admittance"));
  ready("admittance");
  EXPECT_EQ(sup_->phase(), Phase::kRunning);
  sup_->stop("down", now_);
  drain();
  EXPECT_THAT(signals_, ElementsAre("admittance:INT"));  // never a signal to a remote service
}

TEST_F(SupervisionTest, RemoteDependencyThatNeverComesFailsTheBringUp) {
  make({def("gateway", {}, RestartPolicy::kAlways, "cell-crane"), def("admittance", {"gateway"})}, {false, true});
  begin();
  pass(milliseconds(10000));
  EXPECT_TRUE(sup_->failed());
  EXPECT_THAT(sup_->failure(), HasSubstr("gateway (host cell-crane) is not READY"));
  EXPECT_THAT(sup_->failure(), HasSubstr("start it on cell-crane"));
  EXPECT_EQ(sup_->phase(), Phase::kDone);
  EXPECT_THAT(spawned_, IsEmpty());
}

TEST(MakePlanTest, SelectsLocalServicesDependenciesAndTheRemoteOnesTheyNeed) {
  ComposeFile f;
  f.path = "/x/compose.yaml";
  f.services = {def("sim", {}, RestartPolicy::kAlways, "cell-robot"),
                def("gateway", {"sim"}, RestartPolicy::kAlways, "cell-crane"), def("world"),
                def("admittance", {"gateway"}, RestartPolicy::kAlways, "cell-robot"),
                def("controller", {"world"}, RestartPolicy::kAlways, "cell-controller")};
  auto names = [](const std::vector<Supervision::Entry>& plan) {
    std::vector<std::string> out;
    for (const auto& e : plan) out.push_back(e.def->name + (e.local ? "" : "@remote"));
    return out;
  };
  // On the robot host: its two services, plus the crane's gateway that admittance waits for.
  EXPECT_THAT(names(make_plan(f, {}, {"cell-robot"})), ElementsAre("sim", "gateway@remote", "world", "admittance"));
  EXPECT_THAT(names(make_plan(f, {}, {"cell-crane"})), ElementsAre("sim@remote", "gateway", "world"));
  EXPECT_THAT(names(make_plan(f, {"world"}, {"cell-crane"})), ElementsAre("world"));
  EXPECT_THROW(make_plan(f, {"controller"}, {"cell-robot"}), std::invalid_argument);
  EXPECT_THROW(make_plan(f, {"ghost"}, {"cell-robot"}), std::invalid_argument);
}

TEST(ExitInfoTest, Describe) {
  EXPECT_EQ(exit_code(3).describe(), "exit code 3");
  EXPECT_EQ(killed(SIGKILL).describe(), "killed by SIGKILL");
  EXPECT_EQ(killed(200).describe(), "killed by signal 200");
  EXPECT_TRUE(exit_code(0).success());
  EXPECT_FALSE(exit_code(1).success());
  EXPECT_FALSE(killed(SIGTERM).success());
}

}  // namespace
}  // namespace rigger::compose

namespace rigger::compose {
namespace {

// The three-host example of docs/deploy.md: each host starts its own services and waits for the
// remote ones its services depend on.
TEST(MakePlanTest, ThreeHostExampleSplitsTheCell) {
  ParseOptions opt;
  opt.env = [](const std::string&) { return std::nullopt; };
  const auto file =
      load_compose(std::string(RIGGER_SOURCE_DIR) + "/tools/rigger_compose/examples/three_hosts.yaml", opt);
  EXPECT_EQ(file.root, std::string(RIGGER_SOURCE_DIR));
  EXPECT_EQ(file.dds_config, std::string(RIGGER_SOURCE_DIR) + "/deploy/cyclonedds-multihost.xml");
  auto names = [&](const std::string& host) {
    std::vector<std::string> out;
    for (const auto& e : make_plan(file, {}, {host})) out.push_back(e.def->name + (e.local ? "" : "@remote"));
    return out;
  };
  EXPECT_THAT(names("cell-crane"), ElementsAre("crane_gateway"));
  EXPECT_THAT(names("cell-robot"),
              ElementsAre("crane_gateway@remote", "robot_driver", "camera", "world_model@remote", "vision_tracker",
                          "admittance_control", "robot-skills", "perception-skills"));
  EXPECT_THAT(names("cell-controller"), ElementsAre("world_model", "robot-skills@remote", "perception-skills@remote",
                                                    "monitor_host", "operator-skills", "task_controller"));
  // Every service is started on exactly one host.
  std::map<std::string, int> started;
  for (const char* host : {"cell-crane", "cell-robot", "cell-controller"})
    for (const auto& e : make_plan(file, {}, {host}))
      if (e.local) ++started[e.def->name];
  EXPECT_EQ(started.size(), file.services.size());
  for (const auto& [name, count] : started) EXPECT_EQ(count, 1) << name;
  // Every configuration it names is in the repository (the real PLC's is a template next to it).
  for (const auto& s : file.services) {
    if (s.config.empty()) continue;
    EXPECT_TRUE(std::filesystem::is_regular_file(s.config)) << s.name << ": " << s.config;
  }
}

}  // namespace
}  // namespace rigger::compose
