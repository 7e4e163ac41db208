// The checked-in configuration reference is what the settings tables say. When this fails, run
// tools/update-config-reference and commit the result.
#include <fstream>
#include <sstream>

#include <gtest/gtest.h>

#include "reference.hpp"

namespace rigger::config_reference {
namespace {

TEST(ConfigReference, CheckedInReferenceIsCurrent) {
  std::ifstream in(std::string(RIGGER_SOURCE_DIR) + "/docs/config-reference.md");
  std::ostringstream text;
  text << in.rdbuf();
  EXPECT_EQ(text.str(), reference_markdown())
      << "docs/config-reference.md is out of date: run tools/update-config-reference";
}

TEST(ConfigReference, NamesEveryConvertedService) {
  const std::string page = reference_markdown();
  for (const char* section :
       {"## task_controller", "## world_model", "## skill_executor", "## monitor_host", "## cad", "## vision_tracker",
        "## echo", "## console", "## cell_sim", "## crane_gateway", "## scripted_operator", "## scripted_executor",
        "## admittance_control", "## ros2_bridge"})
    EXPECT_NE(page.find(section), std::string::npos) << section;
  EXPECT_NE(page.find("| `command_lease_ms` | integer | `150` | `[100, 10000]` | ms |"), std::string::npos);
  EXPECT_NE(page.find("| `plc/port` | integer | `1502` | `[1, 65535]` |"), std::string::npos);  // a nested key
  EXPECT_NE(page.find("| `robot/gains/damping` | array of numbers | `[100, 100, 100, 10, 10, 10]` |"),
            std::string::npos);
  EXPECT_NE(page.find("| `joint_states/kinematics` | object | `required` |"), std::string::npos);
}

}  // namespace
}  // namespace rigger::config_reference
