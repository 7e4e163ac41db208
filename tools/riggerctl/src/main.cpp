#include <exception>
#include <iostream>

#include "commands.hpp"
#include "rigger/service/service.hpp"

int main(int argc, char** argv) {
  CLI::App app{"riggerctl: the rigger command-line client", "riggerctl"};
  app.require_subcommand(1);
  rigger::ctl::CommonOptions common;
  int exit_code = 0;
  try {
    common.domain = rigger::dds::domain_from_environment(0);
  } catch (const std::exception& e) {
    std::cerr << "riggerctl: " << e.what() << "\n";
    return 2;
  }
  app.add_option("--domain", common.domain, "DDS domain id (default: $RIGGER_DOMAIN or 0)")->check(CLI::Range(0, 232));
  rigger::ctl::add_services_command(app, common, exit_code);
  rigger::ctl::add_task_commands(app, common, exit_code);
  rigger::ctl::add_operator_command(app, common, exit_code);
  rigger::ctl::add_jog_command(app, common, exit_code);
  rigger::ctl::add_sim_command(app, common, exit_code);
  rigger::ctl::add_estop_command(app, common, exit_code);
  rigger::ctl::add_crane_command(app, common, exit_code);
  rigger::ctl::add_topic_commands(app, common, exit_code);
  rigger::ctl::add_cell_command(app, common, exit_code);
  rigger::ctl::add_calibrate_command(app, common, exit_code);
  rigger::ctl::add_cad_command(app, exit_code);
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e) == 0 ? 0 : 2;
  } catch (const std::exception& e) {
    std::cerr << "riggerctl: " << e.what() << "\n";
    return 1;
  }
  return exit_code;
}
