#include "cell_sim_config.hpp"

#include <gtest/gtest.h>

#include <fstream>

namespace rigger::cell_sim {
namespace {

using namespace std::chrono_literals;

/// The ConfigError's message from reading `text`, or "" when it was accepted.
std::string error_of(const std::string& text) {
  try {
    const Config config = Config::parse(text, "test.json");
    read_cell_sim_config(config);
    config.finish();
  } catch (const ConfigError& e) {
    return e.what();
  }
  return "";
}

TEST(CellSimConfig, DefaultsUseTheRepositoryCellAndItsCraneLimits) {
  const CellSimConfig c = read_cell_sim_config(Config::empty());
  EXPECT_EQ(c.cell_file, default_cell_file());
  EXPECT_DOUBLE_EQ(c.real_time_factor, 1.0);
  // simulated_cell.json: rail 4.5 m, rope 0.5..3.8 m -> hook height 0.7..4.0 m.
  EXPECT_NEAR(c.plc.program.limits.position_min_m.z(), 0.7, 1e-9);
  EXPECT_NEAR(c.plc.program.limits.position_max_m.z(), 4.0, 1e-9);
  EXPECT_NEAR(c.plc.program.limits.max_speed_mps.x(), 0.5, 1e-9);
  EXPECT_EQ(c.plc.server.port, 1502);
  EXPECT_TRUE(c.camera_enabled);
  EXPECT_FALSE(c.camera_rate_hz.has_value());
}

TEST(CellSimConfig, TheShippedConfigurationIsValid) {
  const Config config = Config::load(std::string(RIGGER_SOURCE_DIR) + "/deploy/config/cell_sim.json");
  const CellSimConfig c = read_cell_sim_config(config);
  EXPECT_NO_THROW(config.finish());
  EXPECT_TRUE(std::filesystem::exists(c.cell_file)) << c.cell_file;
  EXPECT_GE(c.wrench_rate_hz, 500.0);
  EXPECT_LE(c.plc.program.heartbeat_timeout, 250ms);
}

TEST(CellSimConfig, RelativePathsAreTakenFromTheConfigurationFilesFolder) {
  const std::string dir = ::testing::TempDir() + "/cell_sim_config_test";
  std::filesystem::create_directories(dir + "/cell");
  std::filesystem::copy_file(default_cell_file(), dir + "/cell/my_cell.json",
                             std::filesystem::copy_options::overwrite_existing);
  std::ofstream(dir + "/sim.json") << R"({"cell_file": "cell/my_cell.json"})";
  const CellSimConfig c = read_cell_sim_config(Config::load(dir + "/sim.json"));
  EXPECT_EQ(c.cell_file, std::filesystem::path(dir) / "cell/my_cell.json");
}

TEST(CellSimConfig, ReadsEveryKey) {
  const Config config = Config::parse(R"({
    "real_time_factor": 0, "max_lag_ms": 20, "status_rate_hz": 10, "ground_truth_rate_hz": 5,
    "robot": {"wrench_rate_hz": 500, "wrench_source": "raw", "state_rate_hz": 50, "max_twist_timeout_ms": 300,
              "wrench_noise": {"force_stddev_n": 1.5}},
    "plc": {"port": 0, "heartbeat_timeout_ms": 120, "quick_stop_decel_mps2": [3, 3, 1.5], "link_up": false},
    "camera": {"enabled": false, "width": 640, "height": 360, "rate_hz": 10, "noise_stddev": 0}
  })",
                                      "test.json");
  const CellSimConfig c = read_cell_sim_config(config);
  EXPECT_NO_THROW(config.finish());
  EXPECT_EQ(c.real_time_factor, 0.0);
  EXPECT_EQ(c.max_lag, 20ms);
  EXPECT_EQ(c.wrench_rate_hz, 500.0);
  EXPECT_EQ(c.wrench_source, WrenchSource::kRaw);
  EXPECT_EQ(c.max_twist_timeout, 300ms);
  EXPECT_EQ(c.physics.twist_timeout, 300ms);
  EXPECT_EQ(c.physics.wrench_noise.force_stddev_n, 1.5);
  EXPECT_EQ(c.plc.server.port, 0);
  EXPECT_EQ(c.plc.program.heartbeat_timeout, 120ms);
  EXPECT_EQ(c.plc.program.quick_stop_decel_mps2, Eigen::Vector3d(3, 3, 1.5));
  EXPECT_FALSE(c.plc_link_up);
  EXPECT_FALSE(c.camera_enabled);
  EXPECT_EQ(c.camera_width_px, 640);
  EXPECT_EQ(*c.camera_rate_hz, 10.0);
  EXPECT_EQ(*c.camera_noise_stddev, 0.0);
}

TEST(CellSimConfig, AnImperfectCameraIsReadAndItsBoundsNamed) {
  const CellSimConfig perfect = read_cell_sim_config(Config::empty());
  EXPECT_TRUE(perfect.camera_pose_error.isApprox(Eigen::Isometry3d::Identity()));
  EXPECT_FALSE(perfect.camera_depth_noise.any());
  const CellSimConfig c = read_cell_sim_config(Config::parse(
      R"({"camera": {"pose_error": {"position_m": [0.02, 0, 0], "rpy_deg": [0, 1.5, 0]},
                     "depth_noise": {"stddev_at_1m_m": 0.0005, "grazing_deg": 75, "edge_gap_m": 0.02}}})",
      "test.json"));
  EXPECT_NEAR(c.camera_pose_error.translation().x(), 0.02, 1e-12);
  EXPECT_NEAR(Eigen::AngleAxisd(c.camera_pose_error.rotation()).angle(), 1.5 * M_PI / 180.0, 1e-12);
  EXPECT_DOUBLE_EQ(c.camera_depth_noise.stddev_at_1m_m, 0.0005);
  EXPECT_DOUBLE_EQ(c.camera_depth_noise.grazing_deg, 75.0);
  EXPECT_DOUBLE_EQ(c.camera_depth_noise.edge_gap_m, 0.02);
  EXPECT_NE(error_of(R"({"camera": {"pose_error": {"position_m": [1, 0, 0]}}})").find("/camera/pose_error/position_m"),
            std::string::npos);
  EXPECT_NE(error_of(R"({"camera": {"pose_error": {"rpy_deg": [0, 90, 0]}}})").find("within ±45"), std::string::npos);
  EXPECT_NE(error_of(R"({"camera": {"depth_noise": {"grazing_deg": 90}}})").find("/camera/depth_noise/grazing_deg"),
            std::string::npos);
}

TEST(CellSimConfig, BadValuesNameTheKeyAndTheExpectation) {
  EXPECT_NE(error_of(R"({"real_time_factor": -1})").find("/real_time_factor"), std::string::npos);
  EXPECT_NE(error_of(R"({"real_time_factor": 0.01})").find("0 (unpaced)"), std::string::npos);
  EXPECT_NE(error_of(R"({"robot": {"wrench_rate_hz": 2000}})").find("/robot/wrench_rate_hz"), std::string::npos);
  EXPECT_NE(error_of(R"({"robot": {"wrench_source": "filtered"}})").find("expected one of external, raw"),
            std::string::npos);
  EXPECT_NE(error_of(R"({"plc": {"heartbeat_timeout_ms": 300}})").find("/plc/heartbeat_timeout_ms"), std::string::npos);
  EXPECT_NE(error_of(R"({"plc": {"port": 70000}})").find("/plc/port"), std::string::npos);
  EXPECT_NE(error_of(R"({"plc": {"quick_stop_decel_mps2": [2, 2]}})").find("3 numbers"), std::string::npos);
  // Below the crane's max acceleration: the PLC program refuses it.
  EXPECT_NE(error_of(R"({"plc": {"quick_stop_decel_mps2": [0.1, 2, 2]}})").find("quick_stop_decel"), std::string::npos);
  EXPECT_NE(error_of(R"({"camera": {"width": 640}})").find("width and height together"), std::string::npos);
  EXPECT_NE(error_of(R"({"camera": {"width": 4000, "height": 2000}})").find("/camera/width"), std::string::npos);
  EXPECT_NE(error_of(R"({"robot": {"wrench_rate": 500}})").find("unknown key"), std::string::npos);
}

// Behind the ROS 2 bridge: the drivers' topics default to ros2_control's broadcaster, MoveIt Servo and a
// camera driver; a name ROS 2 refuses is an error at its key.
TEST(CellSimConfig, Ros2DriverTopicsDefaultToTheUsualDriversAndAreCheckedByRos2Rules) {
  EXPECT_FALSE(read_cell_sim_config(Config::empty()).ros2_driver.has_value());
  const Config config = Config::parse(R"({"ros2_driver": {"image_topic": "/cam/image", "twist_timeout_ms": 50}})",
                                      "test.json");
  const CellSimConfig c = read_cell_sim_config(config);
  config.finish();
  ASSERT_TRUE(c.ros2_driver.has_value());
  EXPECT_EQ(c.ros2_driver->wrench_dds_topic, "rt/force_torque_sensor_broadcaster/wrench");
  EXPECT_EQ(c.ros2_driver->twist_dds_topic, "rt/servo_node/delta_twist_cmds");
  EXPECT_EQ(c.ros2_driver->image_dds_topic, "rt/cam/image");
  EXPECT_EQ(c.ros2_driver->base_frame, "base_link");
  EXPECT_EQ(c.ros2_driver->twist_timeout, 50ms);
  EXPECT_EQ(c.ros2_driver->joint_states_dds_topic, "rt/joint_states");
  EXPECT_EQ(c.ros2_driver->joint_names.front(), "joint_a1");
  EXPECT_EQ(c.ros2_driver->joint_names.back(), "joint_a7");
  EXPECT_NE(error_of(R"({"ros2_driver": {"wrench_topic": "/ft sensor"}})").find("/ros2_driver/wrench_topic"),
            std::string::npos);
  EXPECT_NE(error_of(R"({"ros2_driver": {"joint_names": ["a1", "a2"]}})").find("/ros2_driver/joint_names"),
            std::string::npos);
}

TEST(CellSimConfig, OutOfRangeAndUnknownKeysNameTheKeyAndTheFile) {
  const std::string range = error_of(R"({"camera": {"blur_sigma_px": 11}})");
  EXPECT_NE(range.find("test.json"), std::string::npos) << range;
  EXPECT_NE(range.find("/camera/blur_sigma_px"), std::string::npos) << range;
  const std::string unknown = error_of(R"({"plc": {"scan_period": 4}})");
  EXPECT_NE(unknown.find("test.json"), std::string::npos) << unknown;
  EXPECT_NE(unknown.find("/plc/scan_period"), std::string::npos) << unknown;
}

TEST(CellSimConfig, AMissingCellFileIsAConfigurationError) {
  const std::string error = error_of(R"({"cell_file": "/nonexistent/cell.json"})");
  EXPECT_NE(error.find("/cell_file"), std::string::npos) << error;
  EXPECT_NE(error.find("/nonexistent/cell.json"), std::string::npos) << error;
}

TEST(CellSimConfig, AnUnknownCraneIsAConfigurationError) {
  EXPECT_NE(error_of(R"({"plc": {"crane_id": "gantry"}})").find("gantry"), std::string::npos);
}

TEST(CellSimConfig, StepsPerPeriod) {
  EXPECT_EQ(steps_per_period(1000.0, 1ms), 1u);
  EXPECT_EQ(steps_per_period(500.0, 1ms), 2u);
  EXPECT_EQ(steps_per_period(30.0, 1ms), 33u);
  EXPECT_EQ(steps_per_period(5000.0, 1ms), 1u);  // never 0
}

}  // namespace
}  // namespace rigger::cell_sim
