#include "task_controller_node.hpp"

int main(int argc, char** argv) {
  std::string journal_override;
  return rigger::service::run_service(
      argc, argv,
      {"task_controller", "Validates recipes and runs them as event-driven behaviour trees over the executors.",
       [&](CLI::App& app) {
         app.add_option("--journal", journal_override, "SQLite journal file (overrides the config's journal_path)");
       },
       [&](rigger::service::ServiceContext& ctx) {
         return std::make_unique<rigger::task_controller::TaskControllerNode>(ctx, journal_override);
       }});
}
