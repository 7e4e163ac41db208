#include <cstring>

#include "auth.hpp"
#include "console_node.hpp"

int main(int argc, char** argv) {
  if (argc > 1 && std::strcmp(argv[1], "make-users") == 0) return rigger::console::make_users_main(argc, argv);
  return rigger::service::run_service(
      argc, argv,
      {"console",
       "The web console: monitor, replay, plots, operator station.",
       {},
       [](rigger::service::ServiceContext& ctx) { return std::make_unique<rigger::console::ConsoleNode>(ctx); }});
}
