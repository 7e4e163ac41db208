// rigger-compose demo: up, the scenario recipe run by riggerctl, down.
#include <errno.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdio>
#include <ctime>
#include <filesystem>

#include "command_support.hpp"
#include "rigger/base/bounded_json.hpp"
#include "rigger/compose/process_util.hpp"
#include "rigger/compose/security.hpp"

namespace rigger::compose::cli {
namespace {

/// Writes fresh users for the compose file's console (its configuration's users_file) with `console
/// make-users` and prints their login links; nothing when the file has no console or it is not built.
void console_logins(const ComposeFile& file) {
  const ServiceDef* console = file.find("console");
  if (!console || access(console->binary.c_str(), X_OK) != 0) return;
  std::string address = "127.0.0.1", users = "/var/tmp/rigger/console-users.json";
  int port = 8080;
  if (!console->config.empty()) {
    const auto parsed = parse_json_file_bounded(console->config);
    const auto& c = parsed.value;
    if (parsed.ok() && c.is_object()) {
      address = c.value("address", address);
      port = c.value("port", port);
      users = c.value("users_file", users);
    }
  }
  const std::string url = "http://" + address + ":" + std::to_string(port);
  std::printf("rigger-compose demo: the console at %s/ — log in with one of these links (new tokens each demo):\n",
              url.c_str());
  std::fflush(stdout);
  SpawnRequest req;
  req.path = console->binary;
  req.args = {"make-users", "--file", users, "--user", "operator:operator", "--user", "programmer:programmer",
              "--user", "viewer:viewer", "--url", url};
  try {
    const int pid = spawn_process(req);
    int status = 0;
    while (waitpid(pid, &status, 0) < 0 && errno == EINTR) {
    }
  } catch (const std::exception& e) {
    std::fprintf(stderr, "rigger-compose demo: cannot run console make-users: %s\n", e.what());
  }
}

}  // namespace

int demo(const GlobalOptions& g, const std::string& recipe_arg, const std::string& operator_mode) {
  const ComposeFile file = load(g);
  if (operator_mode != "scripted" && operator_mode != "browser")
    fail("--operator " + operator_mode + ": expected scripted or browser", kExitUsage);
  console_logins(file);
  // --operator browser: everything but the scripted operator, so a person answers at the console.
  std::vector<std::string> services;
  if (operator_mode == "browser") {
    for (const auto& s : file.services)
      if (s.name != "scripted_operator") services.push_back(s.name);
    std::printf("rigger-compose demo: no scripted operator: answer the screw prompts at the console's Operator station\n");
  }
  const int up_code = up(g, services);
  if (up_code != kExitOk) return up_code;

  const std::string riggerctl = file.bin_dir + "/riggerctl";
  const std::string recipe =
      !recipe_arg.empty() && recipe_arg.front() == '/' ? recipe_arg : file.root + "/" + recipe_arg;
  std::string missing;
  if (access(riggerctl.c_str(), X_OK) != 0)
    missing = file.display_path(riggerctl) + " not found — not built yet?";
  else if (access(recipe.c_str(), R_OK) != 0)
    missing = "recipe " + file.display_path(recipe) + " not found — not written yet?";
  int code = kExitOk;
  if (!missing.empty()) {
    std::fflush(stdout);
    std::fprintf(stderr, "rigger-compose demo: %s; stopping the cell\n", missing.c_str());
    code = kExitFailure;
  } else {
    std::printf("rigger-compose demo: %s run %s\n", file.display_path(riggerctl).c_str(),
                file.display_path(recipe).c_str());
    std::fflush(stdout);
    SpawnRequest req;
    req.path = riggerctl;
    // A task id is used once (the journal keeps every task): each demo run submits under a new one.
    char stamp[32];
    const std::time_t now = std::time(nullptr);
    std::tm tm{};
    localtime_r(&now, &tm);
    std::strftime(stamp, sizeof stamp, "%Y%m%d-%H%M%S", &tm);
    const std::string task_id = std::filesystem::path(recipe).stem().string() + "-" + stamp;
    req.args = {"--domain", std::to_string(file.domain), "run", recipe, "--task-id", task_id};
    req.env["RIGGER_DOMAIN"] = std::to_string(file.domain);
    if (!file.dds_config.empty()) req.env["CYCLONEDDS_URI"] = file.dds_uri();
    if (g.secure) req.env["RIGGER_IDENTITY"] = kRiggerctlIdentity;
    // Ctrl-C goes to riggerctl (same terminal process group), which cancels the task; we then still
    // bring the cell down.
    struct sigaction ignore {
    }, old_int{}, old_term{};
    ignore.sa_handler = SIG_IGN;
    sigaction(SIGINT, &ignore, &old_int);
    sigaction(SIGTERM, &ignore, &old_term);
    const auto t0 = Clock::now();
    try {
      const int pid = spawn_process(req);
      int status = 0;
      while (waitpid(pid, &status, 0) < 0 && errno == EINTR) {
      }
      const bool clean = WIFEXITED(status) && WEXITSTATUS(status) == 0;
      std::printf("rigger-compose demo: riggerctl %s after %.1f s\n",
                  clean ? "succeeded"
                        : (WIFEXITED(status) ? ("failed with exit code " + std::to_string(WEXITSTATUS(status))).c_str()
                                             : "was killed"),
                  seconds_since(t0));
      code = clean ? kExitOk : kExitFailure;
    } catch (const std::exception& e) {
      std::fprintf(stderr, "rigger-compose demo: cannot run riggerctl: %s\n", e.what());
      code = kExitFailure;
    }
    sigaction(SIGINT, &old_int, nullptr);
    sigaction(SIGTERM, &old_term, nullptr);
  }
  int down_code = kExitFailure;
  try {
    down_code = down(g);
  } catch (const CommandError& e) {
    std::fprintf(stderr, "rigger-compose: %s\n", e.message.c_str());
  }
  return code != kExitOk ? code : down_code;
}

}  // namespace rigger::compose::cli
