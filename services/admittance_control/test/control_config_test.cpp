#include "control_config.hpp"
#include "rigger/cell_config/cell_cad.hpp"

#include <filesystem>
#include <fstream>
#include <string>

#include <gtest/gtest.h>

namespace rigger::control {
namespace {

const std::string kSource = RIGGER_SOURCE_DIR;

// The ConfigError raised by parsing `text`, or an empty pointer "<none>" when it parsed.
ConfigError error_for(const std::string& text) {
  try {
    load_control_config(Config::parse(text, "test.json"));
  } catch (const ConfigError& e) {
    return e;
  }
  return ConfigError("test.json", "<none>", "no error");
}

TEST(ControlConfig, TheShippedFileParsesToTheDocumentedDefaults) {
  const ControlConfig c =
      load_control_config_file(kSource + "/services/admittance_control/config/admittance_control.json");
  const ControlConfig defaults = load_control_config(Config::empty());
  EXPECT_EQ(c.robot_rate_hz, 500.0);
  EXPECT_EQ(c.crane_rate_hz, 50.0);
  EXPECT_EQ(c.robot.gains.mass, defaults.robot.gains.mass);
  EXPECT_EQ(c.robot.gains.damping, defaults.robot.gains.damping);
  EXPECT_EQ(c.robot.deadband, defaults.robot.deadband);
  EXPECT_EQ(c.robot.limits.max_velocity, defaults.robot.limits.max_velocity);
  EXPECT_EQ(c.robot.tcp_in_sensor_m, Eigen::Vector3d(0.0, 0.0, 0.12));  // the cell's flange-to-face
  EXPECT_EQ(c.crane.gains.damping_ns_per_m, defaults.crane.gains.damping_ns_per_m);
  EXPECT_EQ(c.crane.deadband_n, defaults.crane.deadband_n);
  EXPECT_EQ(c.crane.selected_axes, defaults.crane.selected_axes);
  EXPECT_NEAR(c.visual_servo.rotation_tolerance_rad, defaults.visual_servo.rotation_tolerance_rad, 1e-15);
  EXPECT_EQ(c.visual_servo.max_linear_speed_mps, defaults.visual_servo.max_linear_speed_mps);
  // The tuning rule of docs/control.md: the crane takes up the pull before the robot yields to it.
  EXPECT_LT(c.crane.deadband_n.x(), c.robot.deadband.x());
  EXPECT_LT(c.crane.deadband_n.y(), c.robot.deadband.y());
  // And the laws accept it.
  EXPECT_NO_THROW(RobotAdmittance{c.robot});
  EXPECT_NO_THROW(CraneAdmittance{c.crane});
  EXPECT_NO_THROW(VisualServo{c.visual_servo});
}

TEST(ControlConfig, ReadsEverySection) {
  const ControlConfig c = load_control_config(Config::parse(R"({
    "robot": { "rate_hz": 250, "frame": "tool", "gains": { "stiffness": [0, 0, 300, 0, 0, 0] },
               "selected_axes": [true, true, true, false, false, false],
               "tool": { "mass_kg": 2.5, "center_of_mass_m": [0, 0, 0.06] }, "wrench_timeout_s": 0.01 },
    "crane": { "selected_axes": [true, true, true], "rope_offset_gain_per_s": 0.4 },
    "visual_servo": { "rotation_tolerance_deg": 2, "min_quality": 0.7, "max_pose_age_s": 0.5 } })",
                                                            "test.json"));
  EXPECT_EQ(c.robot_rate_hz, 250.0);
  EXPECT_EQ(c.robot.frame, ControlFrame::kTool);
  EXPECT_EQ(c.robot.gains.stiffness[2], 300.0);
  EXPECT_FALSE(c.robot.selected_axes[3]);
  EXPECT_EQ(c.robot.tool.mass_kg, 2.5);
  EXPECT_EQ(c.robot.wrench_timeout, Seconds(0.01));
  EXPECT_TRUE(c.crane.selected_axes[2]);
  EXPECT_EQ(c.crane.rope_offset_gain_per_s, 0.4);
  EXPECT_NEAR(c.visual_servo.rotation_tolerance_rad, 2.0 * kPi / 180.0, 1e-15);
  EXPECT_EQ(c.visual_servo.min_quality, 0.7);
  EXPECT_EQ(c.visual_servo.max_pose_age, Seconds(0.5));
  // Without a stop deceleration of its own, a stop ramps at the acceleration limit.
  EXPECT_EQ(c.robot.limits.stop_deceleration, c.robot.limits.max_acceleration);
  EXPECT_EQ(c.crane.stop_deceleration_mps2, c.crane.max_acceleration_mps2);
}

TEST(ControlConfig, ReadsTheNodesKeys) {
  const ControlConfig d = load_control_config(Config::empty());
  EXPECT_EQ(d.twist_timeout_s, 0.05);
  EXPECT_FALSE(d.cell_file.has_value());
  EXPECT_EQ(d.robot_id, "robot");
  const ControlConfig c = load_control_config(Config::parse(R"({
    "twist_timeout_s": 0.1, "crane_timeout_s": 0.5, "robot_id": "arm", "crane_state_timeout_s": 1,
    "commander_grace_s": 3, "rope_object": "crate", "rope_offset_max_age_s": 0.5,
    "robot": { "limits": { "max_acceleration": [1, 1, 1, 2, 2, 2], "stop_deceleration": [2, 2, 2, 4, 4, 4] } } })",
                                                            "test.json"));
  EXPECT_EQ(c.twist_timeout_s, 0.1);
  EXPECT_EQ(c.crane_timeout_s, 0.5);
  EXPECT_EQ(c.robot_id, "arm");
  EXPECT_EQ(c.crane_state_timeout_s, 1.0);
  EXPECT_EQ(c.commander_grace_s, 3.0);
  EXPECT_EQ(c.rope_object, "crate");
  EXPECT_EQ(c.rope_offset_max_age_s, 0.5);
  EXPECT_EQ(c.robot.limits.stop_deceleration[3], 4.0);
}

// Every key has a row in the reference, each with its range; the nested ones under their section.
TEST(ControlConfig, TheTableDescribesEveryKeyWithItsRange) {
  const auto rows = describe(control_settings());
  EXPECT_GE(rows.size(), 50u);
  for (const auto& row : rows) {
    if (row.type == "number" || row.type == "array of numbers") {
      EXPECT_FALSE(row.range_text.empty()) << row.key;
    }
    EXPECT_FALSE(row.description.empty()) << row.key;
  }
  const auto find = [&](const std::string& key) {
    for (const auto& row : rows)
      if (row.key == key) return row;
    return SettingInfo{};
  };
  EXPECT_EQ(find("robot/gains/damping").default_text, "[100, 100, 100, 10, 10, 10]");
  EXPECT_EQ(find("robot/gains/damping").unit, "N·s/m, N·m·s/rad");
  EXPECT_EQ(find("crane/max_acceleration_mps2").unit, "m/s²");
  EXPECT_EQ(find("visual_servo/rotation_tolerance_deg").range_text, "[1e-06, 180]");
}

TEST(ControlConfig, ErrorsNameThePointerAndWhatWasExpected) {
  struct Case {
    const char* text;
    const char* pointer;
    const char* words;
  };
  const Case cases[] = {
      {R"({"robot": {"gains": {"damping": [100, 100, 0, 10, 10, 10]}}})", "/robot/gains/damping/2", "for axis z"},
      {R"({"robot": {"gains": {"mass": [10, 10, 10]}}})", "/robot/gains/mass", "6 numbers"},
      {R"({"robot": {"frame": "world"}})", "/robot/frame", "base, tool"},
      {R"({"robot": {"selected_axes": [true, 1, true, true, true, true]}})", "/robot/selected_axes", "booleans"},
      {R"({"robot": {"limits": {"max_acceleration": [1, 1, 1, 2, 2, -2]}}})", "/robot/limits/max_acceleration/5", "rz"},
      {R"({"robot": {"wrench_timeout_s": "fast"}})", "/robot/wrench_timeout_s", "a number"},
      {R"({"robot": {"rate_hz": 10}})", "/robot/rate_hz", "max_time_step_s"},
      {R"({"crane": {"robot_velocity_feedforward": 2}})", "/crane/robot_velocity_feedforward", "[0, 1]"},
      {R"({"crane": {"gains": {"mass_kg": [150, -1, 150]}}})", "/crane/gains/mass_kg/1", "for axis y"},
      {R"({"visual_servo": {"rotation_tolerance_deg": 0}})", "/visual_servo/rotation_tolerance_deg", "["},
      {R"({"visual_servo": {"max_pose_age_s": 0}})", "/visual_servo/max_pose_age_s", "[0.001, 60]"},
      {R"({"robot": {"dampnig": [1, 1, 1, 1, 1, 1]}})", "/robot/dampnig", "unknown key"},
      {R"({"commander_grace_s": 20})", "/commander_grace_s", "[0.1, 10]"},
      {R"({"robot": {"tool": {"center_of_mass_m": [0, 0, "x"]}}})", "/robot/tool/center_of_mass_m", "number"},
      {R"({"robots": {}})", "/robots", "unknown key"},
  };
  for (const Case& k : cases) {
    const ConfigError e = error_for(k.text);
    EXPECT_EQ(e.pointer(), k.pointer) << k.text << "\n" << e.what();
    EXPECT_NE(std::string(e.what()).find(k.words), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("test.json"), std::string::npos) << e.what();
  }
}

TEST(InsertionOffset, IsReadFromTheLoadFeaturesAsTheWorldModelAnswersThem) {
  // The world model derives the load's insertion from the STEP models and answers it in the cell file's
  // features form; the shipped cell's is 0.10 m above the target's frame, unrotated.
  const cell::CellFile cell = cell::load_cell_file_with_cad(kSource + "/deploy/cell/simulated_cell.json");
  const Eigen::Isometry3d derived = cell.require("load", "the test").features.insertion.value().pose_target_entity;
  EXPECT_NEAR((derived.translation() - Eigen::Vector3d(0.0, 0.0, 0.10)).norm(), 0.0, 1e-9);
  EXPECT_NEAR((derived.linear() - Eigen::Matrix3d::Identity()).norm(), 0.0, 1e-9);
  const Eigen::Vector3d t = derived.translation();
  const nlohmann::json features = {
      {"insertion",
       {{"target", "target"}, {"pose_in_target", {{"position_m", {t.x(), t.y(), t.z()}}, {"rpy_deg", {0, 0, 0}}}}}}};
  const Eigen::Isometry3d offset = insertion_offset_from_features(features, "features of load");
  EXPECT_NEAR((offset.translation() - derived.translation()).norm(), 0.0, 1e-12);
  EXPECT_NEAR((offset.linear() - Eigen::Matrix3d::Identity()).norm(), 0.0, 1e-12);
}

TEST(InsertionOffset, RollPitchYawFollowTheCellConvention) {
  // R = Rz(yaw) Ry(pitch) Rx(roll): with roll 90 and yaw 90, the x axis goes to y and y goes to z.
  const Eigen::Isometry3d p =
      pose_from_config_json(nlohmann::json::parse(R"({"position_m": [1, 2, 3], "rpy_deg": [90, 0, 90]})"), "t", "/p");
  EXPECT_NEAR((p.linear() * Eigen::Vector3d::UnitX() - Eigen::Vector3d::UnitY()).norm(), 0.0, 1e-12);
  EXPECT_NEAR((p.linear() * Eigen::Vector3d::UnitY() - Eigen::Vector3d::UnitZ()).norm(), 0.0, 1e-12);
  EXPECT_EQ(p.translation(), Eigen::Vector3d(1.0, 2.0, 3.0));
}

TEST(InsertionOffset, MissingOrMalformedFeaturesAreNamed) {
  auto pointer_of = [](const char* text) {
    try {
      insertion_offset_from_features(nlohmann::json::parse(text), "features of load");
    } catch (const ConfigError& e) {
      EXPECT_NE(std::string(e.what()).find("features of load"), std::string::npos);
      return e.pointer();
    }
    return std::string("<none>");
  };
  EXPECT_EQ(pointer_of(R"({"markers": {}})"), "/insertion");
  EXPECT_EQ(pointer_of(R"({"insertion": {"target": "target"}})"), "/insertion/pose_in_target");
  EXPECT_EQ(pointer_of(R"({"insertion": {"pose_in_target": {"position_m": [0, 0], "rpy_deg": [0, 0, 0]}}})"),
            "/insertion/pose_in_target/position_m");
  EXPECT_EQ(pointer_of(R"({"insertion": {"pose_in_target": {"position_m": [0, 0, 0], "rpy_deg": [0, "x", 0]}}})"),
            "/insertion/pose_in_target/rpy_deg");
  EXPECT_EQ(pointer_of(R"({"insertion": {"pose_in_target": {"position_m": [0, 0, 0], "rpy": [0, 0, 0]}}})"),
            "/insertion/pose_in_target/rpy");
  EXPECT_EQ(pointer_of(R"([1, 2])"), "");
}

TEST(CellFile, TheRobotBaseIsReadFromTheCellFile) {
  const Eigen::Isometry3d base = entity_pose_from_cell_file(kSource + "/deploy/cell/simulated_cell.json", "robot");
  EXPECT_TRUE(base.translation().isApprox(Eigen::Vector3d(2.55, 2.0, 0.9), 1e-12));
  EXPECT_TRUE(base.linear().isIdentity(1e-12));
}

TEST(CellFile, ErrorsNameTheFileAndTheEntity) {
  const std::string cell = kSource + "/deploy/cell/simulated_cell.json";
  try {
    entity_pose_from_cell_file(cell, "no_such_robot");
    FAIL() << "no error";
  } catch (const ConfigError& e) {
    EXPECT_EQ(e.file(), cell);
    EXPECT_NE(std::string(e.what()).find("no_such_robot"), std::string::npos) << e.what();
  }
  // The gripper's parent is the robot, not the world: refused rather than resolved wrongly.
  EXPECT_THROW(entity_pose_from_cell_file(cell, "gripper"), ConfigError);
  EXPECT_THROW(entity_pose_from_cell_file(kSource + "/no/such/cell.json", "robot"), ConfigError);
}

TEST(CellFile, TheDeployedConfigurationPlacesTheBaseFromTheCellFile) {
  // deploy/config/admittance_control.json names the cell file relative to itself.
  const ControlConfig c = load_control_config(Config::load(kSource + "/deploy/config/admittance_control.json"));
  ASSERT_TRUE(c.cell_file.has_value());
  EXPECT_TRUE(std::filesystem::equivalent(*c.cell_file, kSource + "/deploy/cell/simulated_cell.json"));
  EXPECT_EQ(c.robot_id, "robot");
  EXPECT_EQ(c.robot.tcp_in_sensor_m, Eigen::Vector3d::Zero());  // cell_sim's wrench is about the tool point
  EXPECT_TRUE(c.crane.selected_axes[2]);                        // the insertion goes down: hoist on
}

}  // namespace
}  // namespace rigger::control
