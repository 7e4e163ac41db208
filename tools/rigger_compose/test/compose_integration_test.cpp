// rigger-compose with real processes: the rigger-compose binary, its supervisor daemon and `echo`
// services, on the test's own DDS domain and log folder. Readiness is read from DDS (the test's own
// ServiceDirectory) and from the supervisor's status file; nothing waits on a sleep.

#include <dirent.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "rigger/compose/process_util.hpp"
#include "rigger/compose/status_file.hpp"
#include "rigger/testing/cell.hpp"

namespace rigger::compose {
namespace {

using ::testing::HasSubstr;
using namespace std::chrono_literals;

struct CommandResult {
  testing::ExitStatus status;
  std::string output;
};

class ComposeIntegrationTest : public testing::MultiProcessTest {
 protected:
  void SetUp() override {
    log_dir_ = cell_.log_dir() + "/compose";
    compose_path_ = cell_.log_dir() + "/compose.yaml";
  }

  void TearDown() override {
    // Whatever happened, leave nothing behind: stop a supervisor still holding our domain.
    if (DomainLock::holder(cell_.domain_id())) {
      const auto r = run({"down"}, 60s);
      EXPECT_EQ(r.status.code, 0) << r.output;
    }
    EXPECT_THAT(processes_on_our_domain(), ::testing::IsEmpty());
    if (HasFailure()) {
      std::cerr << "----- supervisor.log\n"
                << read_text_file(LogLayout(log_dir_).supervisor_log()).value_or("(none)") << "\n";
    }
    MultiProcessTest::TearDown();
  }

  // A compose file on the test's domain, its services taken from `services_yaml`.
  void write_compose(const std::string& services_yaml) {
    std::ofstream out(compose_path_);
    out << "root: " << RIGGER_SOURCE_DIR << "\n"
        << "bin_dir: " << testing::bin_dir() << "\n"
        << "dds: {domain: " << cell_.domain_id() << ", config: deploy/cyclonedds.xml}\n"
        << "log_dir: " << log_dir_ << "\n"
        << "services:\n"
        << services_yaml;
  }

  CommandResult run(const std::vector<std::string>& args, std::chrono::milliseconds timeout) {
    std::vector<std::string> full{"--file", compose_path_};
    full.insert(full.end(), args.begin(), args.end());
    const std::string log = cell_.log_dir() + "/cmd-" + std::to_string(++commands_) + "-" + args.front() + ".out";
    testing::ChildProcess p("rigger-compose", full, {}, log);
    auto st = p.wait(timeout);
    if (!st) {
      p.signal(SIGKILL);
      st = p.wait(5s);
      ADD_FAILURE() << "rigger-compose " << args.front() << " did not finish within " << timeout.count() << " ms";
    }
    return {st.value_or(testing::ExitStatus{}), p.log()};
  }

  SupervisorStatus status() {
    auto st = read_status_file(LogLayout(log_dir_).status_file());
    EXPECT_TRUE(st) << "no status file in " << log_dir_;
    return st.value_or(SupervisorStatus{});
  }

  int status_pid(const std::string& service) {
    const auto st = status();
    const auto* e = st.find(service);
    return e ? e->pid : 0;
  }

  // READY on DDS, announced by process `pid` (0: any).
  bool ready_on_dds(const std::string& id, int pid = 0) {
    const auto& known = cell_.directory().services();
    auto it = known.find(id);
    return it != known.end() && it->second.alive && it->second.status == service::ServiceStatus::kReady &&
           (pid == 0 || it->second.pid == pid);
  }

  // Every process on this machine whose command line carries our domain id: the services the
  // supervisor starts get `--domain <id>`. Catches leftovers whatever their PID.
  std::vector<int> processes_on_our_domain() {
    std::vector<int> out;
    const std::string needle = std::string("--domain") + '\0' + std::to_string(cell_.domain_id()) + '\0';
    DIR* d = opendir("/proc");
    if (!d) return out;
    while (dirent* e = readdir(d)) {
      const int pid = std::atoi(e->d_name);
      if (pid <= 0 || pid == getpid()) continue;
      const auto cmdline = read_text_file("/proc/" + std::to_string(pid) + "/cmdline");
      if (!cmdline || cmdline->find(needle) == std::string::npos) continue;
      if (cmdline->find("rigger-compose") != std::string::npos && cmdline->find("supervise") == std::string::npos)
        continue;
      if (parent_of(pid) == getpid()) continue;  // started by the test itself (cell_.start), not by rigger-compose
      if (process_alive(pid)) out.push_back(pid);
    }
    closedir(d);
    return out;
  }

  static int parent_of(int pid) {
    const auto stat = read_text_file("/proc/" + std::to_string(pid) + "/stat").value_or("");
    const auto close_paren = stat.rfind(')');
    if (close_paren == std::string::npos) return 0;
    std::istringstream in(stat.substr(close_paren + 2));
    char state = 0;
    int ppid = 0;
    in >> state >> ppid;
    return ppid;
  }

  std::string log_dir_;
  std::string compose_path_;
  int commands_ = 0;
};

const char* kFourEchoes = R"(
  echo-a: {binary: echo, restart: always}
  echo-b: {binary: echo, depends_on: [echo-a], restart: always}
  echo-c: {binary: echo, depends_on: [echo-a], restart: on-failure}
  echo-d: {binary: echo, depends_on: [echo-b, echo-c], restart: always, stop_timeout_s: 5}
)";

TEST_F(ComposeIntegrationTest, UpPsKillRestartDown) {
  const std::vector<std::string> ids{"echo-a", "echo-b", "echo-c", "echo-d"};
  write_compose(kFourEchoes);

  // up: returns once everything is READY, with a line per service.
  auto r = run({"up"}, 60s);
  ASSERT_EQ(r.status.code, 0) << r.output;
  for (const auto& id : ids) EXPECT_THAT(r.output, HasSubstr(id + " READY (pid")) << r.output;
  auto st = status();
  EXPECT_EQ(st.phase, "running");
  ASSERT_EQ(st.services.size(), 4u);
  std::map<std::string, int> pids;
  for (const auto& s : st.services) {
    EXPECT_EQ(s.state, "ready") << s.name;
    EXPECT_GT(s.pid, 0) << s.name;
    EXPECT_EQ(s.restarts, 0) << s.name;
    pids[s.name] = s.pid;
  }
  const int supervisor_pid = st.supervisor_pid;
  EXPECT_TRUE(process_alive(supervisor_pid));
  EXPECT_EQ(read_text_file(LogLayout(log_dir_).pid_file()).value_or(""), std::to_string(supervisor_pid) + "\n");
  // The services announce READY on the domain, each from the process the supervisor started.
  ASSERT_TRUE(cell_.wait_until(
      [&] {
        for (const auto& id : ids)
          if (!ready_on_dds(id, pids[id])) return false;
        return true;
      },
      10s));
  // Dependency order: echo-d started after echo-b and echo-c were READY.
  st = status();
  EXPECT_GE(st.find("echo-d")->started_unix_ms, st.find("echo-b")->ready_unix_ms);
  EXPECT_GE(st.find("echo-d")->started_unix_ms, st.find("echo-c")->ready_unix_ms);
  EXPECT_GE(st.find("echo-b")->started_unix_ms, st.find("echo-a")->ready_unix_ms);

  // A second supervisor for the same domain is refused, and nothing changes.
  r = run({"up"}, 30s);
  EXPECT_EQ(r.status.code, 1) << r.output;
  EXPECT_THAT(r.output, HasSubstr("a supervisor already runs for DDS domain " + std::to_string(cell_.domain_id())));
  EXPECT_EQ(status().supervisor_pid, supervisor_pid);

  // ps merges the supervisor's view with DDS.
  r = run({"ps", "--json"}, 30s);
  ASSERT_EQ(r.status.code, 0) << r.output;
  const auto ps = nlohmann::json::parse(r.output);
  EXPECT_EQ(ps.at("supervisor_pid").get<int>(), supervisor_pid);
  EXPECT_EQ(ps.at("phase"), "running");
  ASSERT_EQ(ps.at("services").size(), 4u);
  for (const auto& row : ps.at("services")) {
    const auto name = row.at("service").get<std::string>();
    EXPECT_EQ(row.at("state"), "READY") << name;
    EXPECT_EQ(row.at("pid").get<int>(), pids[name]) << name;
    EXPECT_EQ(row.at("restarts").get<int>(), 0) << name;
    EXPECT_GE(row.at("uptime_ms").get<int>(), 0) << name;
  }
  r = run({"ps"}, 30s);
  ASSERT_EQ(r.status.code, 0) << r.output;
  EXPECT_THAT(r.output, HasSubstr("SERVICE"));
  EXPECT_THAT(r.output, HasSubstr("echo-d"));

  r = run({"logs", "echo-a", "-n", "50"}, 30s);
  ASSERT_EQ(r.status.code, 0) << r.output;
  EXPECT_THAT(r.output, HasSubstr("rigger-compose"));  // the supervisor's start line heads each instance
  EXPECT_NE(run({"logs", "ghost"}, 30s).status.code, 0);

  // SIGKILL one service: the supervisor restarts it (backoff 0.5 s) and it is READY again.
  const int killed_pid = pids["echo-b"];
  ASSERT_EQ(kill(killed_pid, SIGKILL), 0);
  ASSERT_TRUE(cell_.wait_until(
      [&] {
        const auto s = read_status_file(LogLayout(log_dir_).status_file());
        const auto* e = s ? s->find("echo-b") : nullptr;
        return e && e->state == "ready" && e->pid != killed_pid && ready_on_dds("echo-b", e->pid);
      },
      15s));
  st = status();
  EXPECT_EQ(st.find("echo-b")->restarts, 1);
  EXPECT_THAT(st.find("echo-b")->last_exit, HasSubstr("killed by SIGKILL"));
  EXPECT_FALSE(process_alive(killed_pid));
  for (const char* other : {"echo-a", "echo-c", "echo-d"}) {  // nobody else was touched
    EXPECT_EQ(st.find(other)->pid, pids[other]) << other;
    EXPECT_EQ(st.find(other)->restarts, 0) << other;
  }
  const auto supervisor_log = read_text_file(LogLayout(log_dir_).supervisor_log()).value_or("");
  EXPECT_THAT(supervisor_log, HasSubstr("echo-b ended (killed by SIGKILL)"));
  EXPECT_THAT(supervisor_log, HasSubstr("restart #1 in 0.5 s"));

  // restart SERVICE: a new instance, READY, the old one gone.
  const int old_c = pids["echo-c"];
  r = run({"restart", "echo-c"}, 60s);
  ASSERT_EQ(r.status.code, 0) << r.output;
  const int new_c = status_pid("echo-c");
  EXPECT_NE(new_c, old_c);
  EXPECT_GT(new_c, 0);
  EXPECT_FALSE(process_alive(old_c));
  EXPECT_THAT(r.output, HasSubstr("echo-c READY again, pid " + std::to_string(new_c)));
  EXPECT_EQ(status().find("echo-c")->restarts, 1);
  EXPECT_NE(run({"restart", "ghost"}, 30s).status.code, 0);

  // down: every service and the supervisor gone, in reverse order, and the domain free again.
  st = status();
  std::vector<int> last_pids;
  for (const auto& s : st.services) last_pids.push_back(s.pid);
  r = run({"down"}, 60s);
  ASSERT_EQ(r.status.code, 0) << r.output;
  EXPECT_TRUE(wait_for_exit(supervisor_pid, 5s));
  EXPECT_FALSE(process_alive(supervisor_pid));
  for (int pid : last_pids) EXPECT_FALSE(process_alive(pid)) << pid;
  EXPECT_THAT(processes_on_our_domain(), ::testing::IsEmpty());
  EXPECT_FALSE(DomainLock::holder(cell_.domain_id()));
  EXPECT_FALSE(read_text_file(LogLayout(log_dir_).pid_file()));
  st = status();
  for (const auto& s : st.services) {
    EXPECT_EQ(s.state, "stopped") << s.name;
    EXPECT_EQ(s.last_exit, "exit code 0") << s.name;  // each stopped cleanly on SIGINT
  }
  EXPECT_TRUE(cell_.wait_until(
      [&] {
        for (const auto& id : ids)
          if (ready_on_dds(id)) return false;
        return true;
      },
      5s));
  const auto log_after = read_text_file(LogLayout(log_dir_).supervisor_log()).value_or("");
  const auto stop_d = log_after.find("echo-d stopped");
  const auto stop_a = log_after.find("echo-a stopped");
  ASSERT_NE(stop_d, std::string::npos);
  ASSERT_NE(stop_a, std::string::npos);
  EXPECT_LT(stop_d, stop_a);  // dependants stop before what they depend on

  r = run({"down"}, 30s);  // idempotent
  EXPECT_EQ(r.status.code, 0) << r.output;
  EXPECT_THAT(r.output, HasSubstr("nothing to stop"));
}

TEST_F(ComposeIntegrationTest, UpSelectedServiceStartsItsDependenciesOnly) {
  write_compose(kFourEchoes);
  const auto r = run({"up", "echo-b"}, 60s);
  ASSERT_EQ(r.status.code, 0) << r.output;
  const auto st = status();
  ASSERT_EQ(st.services.size(), 2u);
  EXPECT_EQ(st.services[0].name, "echo-a");
  EXPECT_EQ(st.services[1].name, "echo-b");
  EXPECT_EQ(run({"down"}, 60s).status.code, 0);
}

TEST_F(ComposeIntegrationTest, FailedBringUpLeavesNothingRunning) {
  // bad exits at once (it ignores the --id/--domain arguments): up must fail, naming it, and stop echo-a.
  write_compose(R"(
  echo-a: {binary: echo}
  bad: {binary: /bin/false, depends_on: [echo-a]}
)");
  const auto r = run({"up"}, 60s);
  EXPECT_EQ(r.status.code, 1) << r.output;
  EXPECT_THAT(r.output, HasSubstr("service bad ended (exit code 1)"));
  EXPECT_THAT(r.output, HasSubstr("before it announced READY"));
  EXPECT_THAT(r.output, HasSubstr("nothing was left running"));
  EXPECT_FALSE(DomainLock::holder(cell_.domain_id()));
  EXPECT_THAT(processes_on_our_domain(), ::testing::IsEmpty());
  const auto st = status();
  EXPECT_EQ(st.phase, "done");
  EXPECT_THAT(st.failure, HasSubstr("service bad"));
  EXPECT_EQ(st.find("echo-a")->state, "stopped");
}

TEST_F(ComposeIntegrationTest, BadComposeFilesStartNothing) {
  struct Case {
    std::string services;
    int exit_code;
    std::vector<std::string> expected;
  };
  const std::vector<Case> cases{
      {"  echo-a: {binary: echo}\n  echo-b: {binary: echo, restrat: always}\n",
       2,
       {"compose.yaml:7: services.echo-b.restrat: unknown key 'restrat'"}},
      {"  echo-a: {binary: echo}\n  cell_sim: {binary: cell_sim_not_built}\n",
       1,
       {"service cell_sim: binary ", "/cell_sim_not_built not found — not built yet?", "nothing started"}},
      {"  echo-a: {binary: echo, depends_on: [echo-b]}\n  echo-b: {binary: echo, depends_on: [echo-a]}\n",
       2,
       {"dependency cycle: echo-a -> echo-b -> echo-a"}},
      {"  echo-a: {binary: echo, config: deploy/config/nope.json}\n",
       1,
       {"service echo-a: config deploy/config/nope.json not found"}},
  };
  for (const auto& c : cases) {
    write_compose(c.services);
    const auto r = run({"up"}, 30s);
    EXPECT_EQ(r.status.code, c.exit_code) << r.output;
    for (const auto& e : c.expected) EXPECT_THAT(r.output, HasSubstr(e));
    EXPECT_FALSE(DomainLock::holder(cell_.domain_id()));
    EXPECT_FALSE(read_text_file(LogLayout(log_dir_).pid_file()));
    EXPECT_FALSE(read_text_file(LogLayout(log_dir_).service_log("echo-a"))) << "echo-a was started";
    EXPECT_THAT(processes_on_our_domain(), ::testing::IsEmpty());
  }
  // Commands on a service the file does not have.
  write_compose("  echo-a: {binary: echo}\n");
  EXPECT_EQ(run({"up", "ghost"}, 30s).status.code, 2);
  const auto r = run({"restart", "echo-a"}, 30s);
  EXPECT_EQ(r.status.code, 1);
  EXPECT_THAT(r.output, HasSubstr("no supervisor runs for DDS domain"));
}

TEST_F(ComposeIntegrationTest, DownStopsTheServicesOfAKilledSupervisor) {
  write_compose("  echo-a: {binary: echo}\n  echo-b: {binary: echo, depends_on: [echo-a]}\n");
  auto r = run({"up"}, 60s);
  ASSERT_EQ(r.status.code, 0) << r.output;
  const auto st = status();
  ASSERT_EQ(kill(st.supervisor_pid, SIGKILL), 0);
  ASSERT_TRUE(wait_for_exit(st.supervisor_pid, 5s));
  EXPECT_FALSE(DomainLock::holder(cell_.domain_id()));  // the kernel released the lock with the process
  EXPECT_TRUE(process_alive(st.find("echo-a")->pid));   // its services outlived it
  r = run({"down"}, 60s);
  EXPECT_EQ(r.status.code, 0) << r.output;
  EXPECT_THAT(r.output,
              HasSubstr("echo-b (pid " + std::to_string(st.find("echo-b")->pid) + ") outlived its supervisor"));
  EXPECT_FALSE(process_alive(st.find("echo-a")->pid));
  EXPECT_FALSE(process_alive(st.find("echo-b")->pid));
  EXPECT_THAT(processes_on_our_domain(), ::testing::IsEmpty());
}

// The console's way (its rehearsal cell on demand): `supervise --in-group` run as the leader of a group of
// its own keeps its services in that group, so that its caller, here the test, ends every one of them by
// the group's id after the supervisor was SIGKILLed and could not stop them.
TEST_F(ComposeIntegrationTest, SuperviseInGroupLeavesItsCallerTheGroupToEnd) {
  write_compose("  echo-a: {binary: echo}\n  echo-b: {binary: echo, depends_on: [echo-a]}\n");
  SpawnRequest req;
  req.path = testing::bin_dir() + "/rigger-compose";
  req.args = {"--file", compose_path_, "supervise", "--in-group"};
  req.log_path = cell_.log_dir() + "/supervise-in-group.out";
  req.new_process_group = true;
  const pid_t supervisor = spawn_process(req);
  ASSERT_TRUE(cell_.wait_until([&] { return ready_on_dds("echo-a") && ready_on_dds("echo-b"); }, 60s))
      << read_text_file(req.log_path).value_or("");
  const int a = cell_.directory().services().at("echo-a").pid;
  const int b = cell_.directory().services().at("echo-b").pid;
  EXPECT_EQ(getpgid(a), supervisor);
  EXPECT_EQ(getpgid(b), supervisor);

  ASSERT_EQ(kill(supervisor, SIGKILL), 0);
  int status = 0;
  ASSERT_EQ(waitpid(supervisor, &status, 0), supervisor);
  EXPECT_TRUE(process_alive(a)) << "a SIGKILLed supervisor stops nothing itself";
  ASSERT_EQ(kill(-supervisor, SIGTERM), 0) << "its services keep the group alive under its id";
  EXPECT_TRUE(wait_for_exit(a, 10s)) << "echo-a (pid " << a << ") outlived the group's SIGTERM";
  EXPECT_TRUE(wait_for_exit(b, 10s)) << "echo-b (pid " << b << ") outlived the group's SIGTERM";
  EXPECT_THAT(processes_on_our_domain(), ::testing::IsEmpty());
}

// One file, two hosts: the service placed on "cell-crane" is not started here; the local service that
// depends on it waits until DDS shows it READY (here an echo the test starts, standing in for the
// supervisor of the other host).
TEST_F(ComposeIntegrationTest, ServicesOnAnotherHostAreWaitedForNotStarted) {
  write_compose(R"(
  gateway: {binary: echo, host: cell-crane, ready_timeout_s: 1}
  echo-a: {binary: echo, depends_on: [gateway]}
)");
  // Nobody runs the gateway: up fails after its ready timeout and says where to start it.
  auto r = run({"up"}, 30s);
  EXPECT_EQ(r.status.code, 1) << r.output;
  EXPECT_THAT(r.output, HasSubstr("gateway runs on host cell-crane: start it there with the same file"));
  EXPECT_THAT(r.output, HasSubstr("service gateway (host cell-crane) is not READY"));
  EXPECT_FALSE(read_text_file(LogLayout(log_dir_).service_log("echo-a")));

  // "up gateway" here is refused: it belongs to the other host.
  r = run({"up", "gateway"}, 30s);
  EXPECT_EQ(r.status.code, 2) << r.output;
  EXPECT_THAT(r.output, HasSubstr("placed on host cell-crane"));

  // The other host's service comes up: echo-a starts.
  cell_.start("gateway", "echo", {"--id", "gateway"});
  ASSERT_TRUE(cell_.wait_ready({"gateway"}, 10s));
  r = run({"up"}, 30s);
  ASSERT_EQ(r.status.code, 0) << r.output;
  EXPECT_THAT(r.output, HasSubstr("gateway READY on host cell-crane"));
  const auto st = status();
  EXPECT_EQ(st.find("gateway")->state, "remote-ready");
  EXPECT_EQ(st.find("gateway")->pid, 0);
  EXPECT_EQ(st.find("echo-a")->state, "ready");
  r = run({"down"}, 30s);
  EXPECT_EQ(r.status.code, 0) << r.output;
  EXPECT_TRUE(cell_.process("gateway").running());  // down never touches another host's services
}

TEST_F(ComposeIntegrationTest, DemoSaysWhatIsMissingAndStillBringsEverythingDown) {
  write_compose("  echo-a: {binary: echo}\n");
  const auto r = run({"demo", "--recipe", "recipes/does_not_exist.json"}, 60s);
  EXPECT_EQ(r.status.code, 1) << r.output;
  EXPECT_THAT(r.output, HasSubstr("echo-a READY"));
  EXPECT_THAT(r.output, HasSubstr("not found"));
  EXPECT_THAT(r.output, HasSubstr("stopped in"));
  EXPECT_FALSE(DomainLock::holder(cell_.domain_id()));
  EXPECT_THAT(processes_on_our_domain(), ::testing::IsEmpty());
}

}  // namespace
}  // namespace rigger::compose
