#include "vision_tracker_node.hpp"

int main(int argc, char** argv) {
  return rigger::service::run_service(
      argc, argv,
      {"vision_tracker",
       "Tracks the cell's marker layouts in camera images.",
       {},
       [](rigger::service::ServiceContext& ctx) { return std::make_unique<rigger::vision::VisionTrackerNode>(ctx); }});
}
