// The rigger-compose command line: options and subcommands; each verb is in <verb>_command.cpp.
#include "rigger/compose/commands.hpp"

#include <CLI/CLI.hpp>
#include <cstdio>
#include <functional>
#include <memory>

#include "command_support.hpp"

namespace rigger::compose {

using namespace cli;

int run_cli(int argc, char** argv) {
  CLI::App app{"rigger-compose: runs the services of a compose file (deploy/compose.yaml) as supervised processes",
               "rigger-compose"};
  app.require_subcommand(1);
  app.fallthrough();
  GlobalOptions g;
  app.add_option("-f,--file", g.file,
                 "Compose file (default: deploy/compose.yaml of the installation, <prefix>/share/rigger)")
      ->multi_option_policy(CLI::MultiOptionPolicy::TakeLast);
  app.add_option("--domain", g.domain, "DDS domain id, overriding dds.domain")->check(CLI::Range(0, 232));
  app.add_option("--host", g.host, "This host's name for `host:` placement (default $RIGGER_HOST, the host name)");
  app.add_flag("--secure", g.secure,
               "DDS Security: the services, rigger-compose and demo's riggerctl join with their identities from "
               "$RIGGER_SECURITY_DIR (default /var/tmp/rigger/security; deploy/security/make-pki makes it) "
               "over deploy/cyclonedds-secure.xml (docs/security.md)");

  int code = kExitOk;
  std::function<int()> action;
  auto* up_cmd = app.add_subcommand("up", "Start the services (and their dependencies); return when all are READY");
  auto up_services = std::make_shared<std::vector<std::string>>();
  up_cmd->add_option("services", *up_services, "Services to start (default: every service of this host)");
  up_cmd->callback([&] { action = [&] { return up(g, *up_services); }; });

  app.add_subcommand("down", "Stop every service in reverse dependency order and the supervisor")->callback([&] {
    action = [&] { return down(g); };
  });

  auto* ps_cmd = app.add_subcommand("ps", "Show the services: supervisor state merged with their DDS state");
  auto ps_json = std::make_shared<bool>(false);
  auto ps_timeout = std::make_shared<double>(2.0);
  ps_cmd->add_flag("--json", *ps_json, "Print JSON");
  ps_cmd->add_option("--timeout", *ps_timeout, "Seconds to wait for DDS discovery (default 2)")
      ->check(CLI::Range(0.1, 60.0));
  ps_cmd->callback([&] { action = [&] { return ps(g, *ps_json, *ps_timeout); }; });

  auto* logs_cmd = app.add_subcommand("logs", "Print a service's log ('supervisor' for the supervisor's)");
  auto logs_service = std::make_shared<std::string>();
  auto logs_follow = std::make_shared<bool>(false);
  auto logs_lines = std::make_shared<int>(0);
  logs_cmd->add_option("service", *logs_service, "Service name")->required();
  logs_cmd->add_flag("-f,--follow", *logs_follow, "Keep printing what is appended (Ctrl-C ends)");
  logs_cmd->add_option("-n,--lines", *logs_lines, "Only the last N lines")->check(CLI::Range(1, 1000000));
  logs_cmd->callback([&] { action = [&] { return logs(g, *logs_service, *logs_follow, *logs_lines); }; });

  auto* restart_cmd = app.add_subcommand("restart", "Restart one service and wait until it is READY again");
  auto restart_service = std::make_shared<std::string>();
  restart_cmd->add_option("service", *restart_service, "Service name")->required();
  restart_cmd->callback([&] { action = [&] { return restart(g, *restart_service); }; });

  auto* demo_cmd = app.add_subcommand("demo", "up, run the scenario recipe with riggerctl while streaming it, down");
  auto demo_recipe = std::make_shared<std::string>("recipes/crane_insert.json");
  demo_cmd->add_option("--recipe", *demo_recipe,
                       "Recipe, relative to the repository root (default recipes/crane_insert.json)");
  auto demo_operator = std::make_shared<std::string>("scripted");
  demo_cmd->add_option("--operator", *demo_operator,
                       "Who answers the operator prompts: scripted (default) or browser (a person at the console)");
  demo_cmd->callback([&] { action = [&] { return demo(g, *demo_recipe, *demo_operator); }; });

  app.add_subcommand("config", "Validate the compose file and show it resolved, in start order")->callback([&] {
    action = [&] { return config(g); };
  });

  // What `up` starts as a daemon; in the foreground it is a process its caller owns (the console's
  // rehearsal cell on demand): SIGTERM or SIGINT stops every service, in reverse order, and then it.
  auto* sup_cmd = app.add_subcommand(
      "supervise", "Run the supervisor in the foreground until SIGTERM/SIGINT, which stops every service");
  auto sup_services = std::make_shared<std::vector<std::string>>();
  auto sup_fd = std::make_shared<int>(-1);
  auto sup_in_group = std::make_shared<bool>(false);
  sup_cmd->add_option("services", *sup_services);
  sup_cmd->add_option("--notify-fd", *sup_fd);
  sup_cmd->add_flag("--in-group", *sup_in_group,
                    "Keep the services in the supervisor's process group, so that its caller ends them with it "
                    "by that group's id even when the supervisor was killed (run it as a group leader)");
  sup_cmd->callback([&] { action = [&] { return supervise(g, *sup_services, *sup_fd, *sup_in_group); }; });

  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e) == 0 ? kExitOk : kExitUsage;
  }
  try {
    code = action ? action() : kExitUsage;
  } catch (const CommandError& e) {
    std::fflush(stdout);
    std::fprintf(stderr, "rigger-compose: %s\n", e.message.c_str());
    code = e.code;
  } catch (const ComposeError& e) {
    std::fprintf(stderr, "rigger-compose: %s\n", e.what());
    code = kExitUsage;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "rigger-compose: %s\n", e.what());
    code = kExitFailure;
  }
  return code;
}

}  // namespace rigger::compose
