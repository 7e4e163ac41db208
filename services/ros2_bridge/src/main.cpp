#include "ros2_bridge_node.hpp"

int main(int argc, char** argv) {
  return rigger::service::run_service(
      argc, argv,
      {"ros2_bridge",
       "Maps rigger's robot topics to a ROS 2 driver's (force-torque wrench, MoveIt Servo twist).",
       {},
       [](rigger::service::ServiceContext& ctx) {
         return std::make_unique<rigger::ros2_bridge::Ros2BridgeNode>(ctx);
       }});
}
