#include "task_controller_node.hpp"

int main(int argc, char** argv) {
  return rigger::dds::run_service(
      argc, argv,
      {"task_controller", "Validates recipes and runs them as event-driven behaviour trees over the executors.", {},
       [](rigger::dds::ServiceContext& ctx) {
         return std::make_unique<rigger::task_controller::TaskControllerNode>(ctx);
       }});
}
