#include "scripted_executor_node.hpp"

int main(int argc, char** argv) {
  return rigger::service::run_service(argc, argv,
                                      {"scripted_executor",
                                       "Announces configured skills and monitors and plays scripted behaviours.",
                                       {},
                                       [](rigger::service::ServiceContext& ctx) {
                                         return std::make_unique<rigger::scripted::ScriptedExecutorNode>(ctx);
                                       }});
}
