#include "reference.hpp"

#include <vector>

#include "rigger/admittance_control/settings.hpp"
#include "rigger/base/settings.hpp"
#include "rigger/cad/settings.hpp"
#include "rigger/cell_sim/settings.hpp"
#include "rigger/console/settings.hpp"
#include "rigger/crane_gateway/settings.hpp"
#include "rigger/echo/settings.hpp"
#include "rigger/monitor_host/settings.hpp"
#include "rigger/ros2_bridge/settings.hpp"
#include "rigger/scripted_executor/settings.hpp"
#include "rigger/scripted_operator/settings.hpp"
#include "rigger/skill_executor/settings.hpp"
#include "rigger/task_controller/settings.hpp"
#include "rigger/vision_tracker/settings.hpp"
#include "rigger/world_model/settings.hpp"

namespace rigger::config_reference {
namespace {

struct Section {
  std::string service;  ///< the folder under services/, and the section's anchor
  std::string about;    ///< one sentence: what the service is, and its shipped configuration file
  std::vector<SettingInfo> settings;
};

std::vector<Section> sections() {
  return {
      {"task_controller",
       "Takes recipes, validates them and runs them as behaviour trees "
       "([behavior-tree.md](behavior-tree.md#the-controllers-configuration-deployconfigtask_controllerjson)).",
       describe(task_controller::controller_settings())},
      {"world_model", "The authoritative store of the cell's entities ([world-model.md](world-model.md)).",
       describe(world::world_model_settings())},
      {"skill_executor",
       "Hosts the built-in skills its configuration names; an executor built on the skill SDK reads the same "
       "keys ([skills.md](skills.md)).",
       describe(skill_executor::skill_executor_settings("<id>"))},
      {"monitor_host", "The executor of the monitors ([skills.md](skills.md)).",
       describe(monitor::monitor_host_settings("<id>"))},
      {"cad", "Answers questions about the STEP models of the cell ([cad.md](cad.md)).",
       describe(cad_service::cad_settings())},
      {"vision_tracker", "Camera images in, object poses out.", describe(vision::vision_tracker_settings())},
      {"echo", "Answers echo requests (the latency benchmarks' peer) and publishes the peers it sees.",
       describe(echo::echo_settings())},
      {"console", "The web gateway: the browser's REST, live streams and pages ([console.md](console.md)).",
       describe(console::console_settings())},
      {"cell_sim",
       "The simulated cell: physics, the robot's and gripper's drivers, the crane PLC emulator, the camera "
       "([cell-sim.md](cell-sim.md#configuration)).",
       describe(cell_sim::cell_sim_settings())},
      {"crane_gateway",
       "The only bridge to the crane PLC, over Modbus TCP ([cell-sim.md](cell-sim.md#the-crane-gateway-process), "
       "[crane-modbus.md](crane-modbus.md)).",
       describe(crane_gateway::gateway_settings())},
      {"scripted_operator", "Answers operator prompts by rule: the demo's and the tests' human.",
       describe(scripted_operator::scripted_operator_settings())},
      {"scripted_executor",
       "A skill executor without hardware: announces skills and monitors and plays scripted behaviours.",
       describe(scripted::scripted_executor_settings())},
      {"admittance_control",
       "The robot and crane admittance laws and the visual servo, and their node; how to tune them is in "
       "[control.md](control.md). A key `robot/gains/mass` is `\"gains\": {\"mass\": …}` in the `robot` object. "
       "After the keys, the rules that relate several are checked: a loop period 1/`rate_hz` within "
       "`max_time_step_s`; `crane/rope_offset_gain_per_s` above 0 needs `cell_file`.",
       describe(control::control_settings())},
      {"ros2_bridge",
       "rigger's robot interface and camera on a ROS 2 driver's topics "
       "([ros2.md](ros2.md#the-bridge-servicesros2_bridge)). "
       "Each stream (`wrench`, `twist_command`, `image`, `joint_states`) is bridged when its object is given; at "
       "least one must be, each on a topic of its own.",
       describe(ros2_bridge::bridge_settings())},
  };
}

}  // namespace

std::string reference_markdown() {
  std::string out =
      "# Configuration reference\n\n"
      "<!-- Generated from the services' settings tables by tools/update-config-reference; do not edit. -->\n\n"
      "The keys of each service's JSON configuration file (`--config`; the shipped ones are in "
      "`deploy/config/`). Every key is optional: an absent key takes its default. A key of the wrong type, "
      "out of its range (inclusive) or unknown stops the service at start (exit 2), naming the file, the "
      "key's JSON pointer and what was expected. Units are in the keys' names (`_s`, `_ms`, `_mm`, `_hz`…). "
      "Each service declares its keys once, in a table of `rigger/base/settings.hpp` descriptors that both "
      "reads the file and writes this page; a unit test fails while the page is stale.\n";
  for (const auto& section : sections()) {
    out += "\n## " + section.service + "\n\n" + section.about + "\n\n" + settings_markdown(section.settings);
  }
  return out;
}

}  // namespace rigger::config_reference
