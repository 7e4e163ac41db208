#include "scripted_executor_node.hpp"

int main(int argc, char** argv) {
  return rigger::dds::run_service(
      argc, argv,
      {"scripted_executor", "Announces configured skills and monitors and plays scripted behaviours.", {},
       [](rigger::dds::ServiceContext& ctx) { return std::make_unique<rigger::scripted::ScriptedExecutorNode>(ctx); }});
}
