// DDS Security with real processes (issue 17, docs/security.md): a PKI made by deploy/security/make-pki
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

#include "rigger/dds/pubsub.hpp"
#include "rigger/dds/qos.hpp"
#include "rigger/protocol/crane.hpp"
#include "rigger/protocol/task.hpp"
#include "rigger/testing/cell.hpp"
#include "../two_step_recipe.hpp"

namespace rigger::testing {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;
using namespace std::chrono_literals;

// The PKI (made once for the test program) and an intruder's folder in which the identity CA also
// plays the permissions CA.
std::string g_base, g_keys, g_pki, g_rogue;

std::string secure_uri() { return std::string("file://") + RIGGER_SOURCE_DIR + "/deploy/cyclonedds-secure.xml"; }
// rigger-compose and the probe of this build (the services may come from $RIGGER_BIN_DIR).
std::string own_binary(const std::string& name) { return std::string(RIGGER_BINARY_DIR) + "/bin/" + name; }

std::string slurp(const std::string& path) {
  std::ifstream in(path);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

void write_text(const std::string& path, const std::string& text) {
  std::ofstream out(path);
  out << text;
}

// Runs a command to its end; its output goes to <g_base>/<name>.log. Returns (status, output).
std::pair<ExitStatus, std::string> run(const std::string& name, const std::string& binary,
                                       const std::vector<std::string>& args,
                                       const std::map<std::string, std::string>& env = {},
                                       std::chrono::milliseconds timeout = 120s) {
  ChildProcess p(binary, args, env, g_base + "/" + name + ".log");
  auto st = p.wait(timeout);
  if (!st) {
    p.signal(SIGKILL);
    st = p.wait(5s);
    ADD_FAILURE() << name << " did not finish within " << timeout.count() << " ms";
  }
  return {st.value_or(ExitStatus{}), p.log()};
}

class SecurityTest : public ::testing::Test {
 public:
  static void SetUpTestSuite() {
    g_base = std::string(RIGGER_BINARY_DIR) + "/test-logs/SecurityTest-" + std::to_string(getpid());
    // Keys never go into the repository (make-pki refuses): a private folder under /tmp.
    g_keys = "/tmp/rigger-security-test-" + std::to_string(getpid());
    g_pki = g_keys + "/pki";
    g_rogue = g_keys + "/rogue";
    fs::create_directories(g_base);
    const auto [made, out] = run("make-pki", std::string(RIGGER_SOURCE_DIR) + "/deploy/security/make-pki",
                                 {"--catalog", own_binary("rigger-topic-catalog"), g_pki});
    ASSERT_TRUE(made.ok()) << out;
    ASSERT_EQ(fs::status(g_pki + "/identities/task_controller/key.pem").permissions() & fs::perms::all,
              fs::perms::owner_read | fs::perms::owner_write);
    make_rogue();
    // The test's own participant (the Cell's) is a permitted reader of everything: identity "observer".
    setenv("CYCLONEDDS_URI", secure_uri().c_str(), 1);
    setenv("RIGGER_SECURITY_DIR", g_pki.c_str(), 1);
    setenv("RIGGER_IDENTITY", "observer", 1);
  }

  static void TearDownTestSuite() {
    if (!g_keys.empty()) fs::remove_all(g_keys);
  }

  // An intruder who holds the identity CA's key (or one who made their own permissions CA and got the
  // cell's identity CA to sign it): a real identity (vision_tracker's certificate and key), permissions
  // granting every topic, signed by the identity CA, which its own configuration trusts as permissions CA.
  static void make_rogue() {
    const std::string id = g_rogue + "/identities/vision_tracker";
    fs::create_directories(id);
    fs::create_directories(g_rogue + "/ca");
    fs::copy_file(g_pki + "/ca/identity_ca.pem", g_rogue + "/ca/identity_ca.pem");
    fs::copy_file(g_pki + "/ca/identity_ca.pem", g_rogue + "/ca/permissions_ca.pem");
    fs::copy_file(g_pki + "/identities/vision_tracker/cert.pem", id + "/cert.pem");
    fs::copy_file(g_pki + "/identities/vision_tracker/key.pem", id + "/key.pem");
    const std::string mine = slurp(g_pki + "/identities/vision_tracker/permissions.xml");
    const auto a = mine.find("<subject_name>"), b = mine.find("</subject_name>");
    ASSERT_NE(a, std::string::npos);
    const std::string subject = mine.substr(a, b - a + 15);
    write_text(id + "/permissions.xml",
               "<?xml version=\"1.0\" encoding=\"utf-8\"?>\n<dds><permissions><grant name=\"everything\">" + subject +
                   "<validity><not_before>2020-01-01T00:00:00</not_before><not_after>2100-01-01T00:00:00</not_after>"
                   "</validity><allow_rule><domains><id_range><min>0</min><max>230</max></id_range></domains>"
                   "<publish><topics><topic>*</topic></topics></publish>"
                   "<subscribe><topics><topic>*</topic></topics></subscribe></allow_rule>"
                   "<default>DENY</default></grant></permissions></dds>\n");
    for (const auto& [in, out] : {std::pair{id + "/permissions.xml", id + "/permissions.p7s"},
                                  std::pair{g_pki + "/governance.xml", g_rogue + "/governance.p7s"}}) {
      const auto [signed_ok, log] =
          run("rogue-sign", "/usr/bin/openssl",
              {"smime", "-sign", "-in", in, "-text", "-out", out, "-signer", g_pki + "/ca/identity_ca.pem", "-inkey",
               g_pki + "/ca/identity_ca.key"});
      ASSERT_TRUE(signed_ok.ok()) << log;
    }
  }

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
    return run(name + "-" + std::to_string(cell_.domain_id()), own_binary("rigger-compose"), args,
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

  std::map<std::string, std::string> secure_env(const std::string& identity, const std::string& pki = g_pki) {
    return {{"CYCLONEDDS_URI", secure_uri()},
            {"RIGGER_SECURITY_DIR", pki},
            {"RIGGER_IDENTITY", identity},
            {"RIGGER_DOMAIN", std::to_string(cell_.domain_id())}};
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
  const std::string domain = std::to_string(cell_.domain_id());
  struct Probe {
    std::string label;
    std::map<std::string, std::string> env;
    std::unique_ptr<ChildProcess> process;
  };
  std::vector<Probe> probes;
  probes.push_back({"no-identity",
                    {{"CYCLONEDDS_URI", default_dds_config_uri()}, {"RIGGER_IDENTITY", ""}, {"RIGGER_SECURITY_DIR", ""}},
                    nullptr});
  probes.push_back({"no-permission", secure_env("vision_tracker"), nullptr});
  probes.push_back({"rogue-permissions", secure_env("vision_tracker", g_rogue), nullptr});
  probes.push_back({"control", secure_env("admittance_control"), nullptr});
  for (auto& p : probes)
    p.process = start("probe-" + p.label, own_binary("rigger_security_probe"),
                      {"--domain", domain, "--label", p.label, "--cancel", task, "--match-window-ms", "2500"}, p.env);
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
  const auto probe_log = [&](const std::string& label) { return slurp(dir_ + "/probe-" + label + ".log"); };
  for (const auto& label : {"no-identity", "no-permission", "rogue-permissions"}) {
    const auto log = probe_log(label);
    for (const auto* topic : {protocol::task::kCommand.name, protocol::task::kRecipe.name, protocol::crane::kCmdVelocity.name}) {
      EXPECT_NE(log.find(std::string(topic) + ": "), std::string::npos) << label << " did not try " << topic << "\n" << log;
      EXPECT_EQ(log.find(std::string(topic) + ": MATCHED"), std::string::npos) << label << " matched a reader of " << topic
                                                                              << "\n" << log;
    }
  }
  // The identity without permission is refused by its own DDS, before anything reaches the wire.
  EXPECT_NE(probe_log("no-permission").find(std::string(protocol::task::kRecipe.name) + ": writer REFUSED locally"),
            std::string::npos)
      << probe_log("no-permission");
  // The permissions signed by the identity CA are rejected by the cell's own DDS, which logs it.
  EXPECT_NE(service_log("task_controller").find("permissions from plugin: Failed to parse PKCS7 SMIME document"),
            std::string::npos)
      << service_log("task_controller");
  EXPECT_NE(probe_log("control").find(std::string(protocol::crane::kCmdVelocity.name) + ": MATCHED"), std::string::npos)
      << probe_log("control");
  EXPECT_NE(probe_log("control").find(std::string(protocol::task::kRecipe.name) + ": writer REFUSED locally"),
            std::string::npos)
      << probe_log("control");
}

}  // namespace
}  // namespace rigger::testing
