// Calibrating the camera on the real processes (cell_sim with MuJoCo, lens distortion and the camera 20 mm and
// 1.5° off its drawing; world_model, vision_tracker, the robot's skill executor, task_controller) on the test's
// own domain: before, the tracker's world pose of the part (by its marker) is off by the camera's error; the arm
// holds the board up to the camera, `riggerctl calibrate camera` runs CalibrateCamera, the world model takes the
// camera's pose as a new revision, cell_sim redraws the camera without moving it and the tracker takes it;
// after, the calibrated camera is within 3 mm and 0.2° of where the camera really is and the part's tracked pose
// within 5 mm of the truth.
#include <cmath>
#include <cstdio>
#include <map>
#include <optional>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "calibration_board_support.hpp"
#include "cell_revision_support.hpp"
#include "rigger/cell_config/cell_file.hpp"
#include "rigger/protocol/robot.hpp"
#include "rigger/protocol/sim.hpp"
#include "rigger/protocol/vision.hpp"

namespace rigger::testing {
namespace {

using namespace std::chrono_literals;
using nlohmann::json;

// The camera's true pose in its drawn optical frame (cell_sim's camera/pose_error): 20.0 mm, 1.50°.
const json kPoseError = {{"position_m", {0.012, -0.010, 0.0125}}, {"rpy_deg", {0.9, -0.85, 0.85}}};

double angle_deg(const Eigen::Matrix3d& r) {
  return Eigen::AngleAxisd(r).angle() * 180.0 / M_PI;
}

class CalibrateCameraProcessTest : public MultiProcessTest {};

TEST_F(CalibrateCameraProcessTest, TheCalibratedCameraIsWhereTheCameraReallyIs) {
  // The lens with distortion: the MuJoCo renderer draws it, the tracker undistorts by the cell file's.
  const std::string cell_file = write_board_cell(cell_.log_dir(), [](json& cell) {
    for (json& entity : cell["entities"])
      if (entity["id"] == "camera") entity["camera"]["distortion"] = {-0.04, 0.01, 0.0, 0.0, 0.0};
  });
  const std::string dir = cell_.log_dir();
  const auto config = [&](const std::string& name, const json& patch = json::object()) {
    return config_on(dir, name, cell_file, patch);
  };
  cell_.start("cell_sim", "cell_sim",
              {"--config", config("cell_sim", {{"plc", {{"port", 0}}},
                                               {"camera", {{"renderer", "mujoco"}, {"pose_error", kPoseError}}}})});
  cell_.start("world_model", "world_model", {"--config", config("world_model"), "--db", dir + "/world.sqlite"});
  cell_.start("vision_tracker", "vision_tracker", {"--config", config("vision_tracker")});
  cell_.start("robot-skills", "skill_executor", {"--id", "robot-skills", "--config", config("robot-skills")});
  cell_.start("task_controller", "task_controller",
              {"--config", config("task_controller", {{"journal_path", dir + "/journal.sqlite"}})});
  ASSERT_TRUE(cell_.wait_ready({"cell_sim", "world_model", "vision_tracker", "robot-skills", "task_controller"}, 90s))
      << cell_.logs();

  const cell::CellFile file = cell::load_cell_file(cell_file);
  const Eigen::Isometry3d world_camera_drawn = file.pose_root_entity("camera");
  const auto vector = [](const json& v) {
    return Eigen::Vector3d(v[0].get<double>(), v[1].get<double>(), v[2].get<double>());
  };
  const Eigen::Isometry3d world_camera_true =
      world_camera_drawn *
      cell::pose_from_position_rpy_deg(vector(kPoseError["position_m"]), vector(kPoseError["rpy_deg"]));
  const Eigen::Isometry3d world_base = file.pose_root_entity("robot");

  std::optional<Eigen::Isometry3d> tool;
  bool moving = true;
  dds::Reader<rigger_robot_RobotState> robot(cell_.participant(), protocol::robot::kState);
  cell_.loop().on_data(robot, [&] {
    robot.take([&](const rigger_robot_RobotState& s, const dds_sample_info_t&) {
      tool = dds::to_domain(s.tool_pose);
      moving = s.moving;
    });
  });
  std::map<std::string, rigger_robot_MotionState> motions;
  dds::Reader<rigger_robot_MotionStatus> status(cell_.participant(), protocol::robot::kMotionStatus);
  cell_.loop().on_data(status, [&] {
    status.take([&](const rigger_robot_MotionStatus& s, const dds_sample_info_t&) {
      motions[dds::to_string(s.motion_id)] = s.state;
    });
  });
  std::map<std::string, Eigen::Isometry3d> truth;
  dds::Reader<rigger_vision_TrackedPose> ground_truth(cell_.participant(), protocol::sim::kGroundTruth);
  cell_.loop().on_data(ground_truth, [&] {
    ground_truth.take([&](const rigger_vision_TrackedPose& p, const dds_sample_info_t&) {
      truth[dds::to_string(p.object_id)] = dds::to_domain(p.pose.pose);
    });
  });
  std::optional<rigger_vision_TrackedPose> seen;
  std::optional<WallTime> asked;
  dds::Reader<rigger_vision_TrackedPose> poses(cell_.participant(), protocol::vision::kTrackerPose);
  cell_.loop().on_data(poses, [&] {
    poses.take([&](const rigger_vision_TrackedPose& p, const dds_sample_info_t&) {
      if (dds::to_string(p.object_id) == "part" && asked && dds::to_domain(p.header.stamp) > *asked) seen = p;
    });
  });
  std::optional<world_protocol::CellRevision> calibrated;
  dds::Reader<rigger_world_CellRevision> revisions(cell_.participant(), protocol::world::kCell);
  cell_.loop().on_data(revisions, [&] {
    revisions.take([&](const rigger_world_CellRevision& wire, const dds_sample_info_t&) {
      world_protocol::CellRevision r = world_protocol::from_wire(wire);
      if (r.who.rfind("CalibrateCamera", 0) == 0) calibrated = std::move(r);
    });
  });
  dds::Writer<rigger_robot_MotionCommand> motion(cell_.participant(), protocol::robot::kCmdMotion);
  dds::Writer<rigger_vision_TrackerCommand> tracker(cell_.participant(), protocol::vision::kTrackerCommand);
  ASSERT_TRUE(motion.wait_for_readers(1, 5s));
  ASSERT_TRUE(tracker.wait_for_readers(1, 5s));
  ASSERT_TRUE(cell_.wait_until([&] { return tool.has_value() && truth.count("part") != 0; }, 10s));
  const Eigen::Isometry3d ready = *tool;

  // The part's world pose as the tracker gives it (one image), and its distance from the truth (mm).
  std::uint64_t seq = 0;
  const auto track_part = [&]() -> std::optional<double> {
    seen.reset();
    asked = std::chrono::system_clock::now();
    rigger_vision_TrackerCommand once{};
    once.header.stamp = dds::to_wire(*asked);
    once.seq = ++seq;
    once.object_id = const_cast<char*>("part");
    once.kind = rigger_vision_TRACK_ONCE;
    once.source = const_cast<char*>("integration-test");
    if (tracker.write(once) != DDS_RETCODE_OK) return std::nullopt;
    if (!cell_.wait_until([&] { return seen.has_value(); }, 20s) || !seen->tracked) return std::nullopt;
    return (dds::to_domain(seen->pose.pose).translation() - truth.at("part").translation()).norm() * 1e3;
  };
  const auto move_tool = [&](const std::string& id, const Eigen::Isometry3d& base_tool) {
    rigger_robot_MotionCommand c{};
    c.header.stamp = dds::to_wire(std::chrono::system_clock::now());
    c.header.frame_id = const_cast<char*>("world");
    c.motion_id = const_cast<char*>(id.c_str());
    c.kind = rigger_robot_MOTION_CARTESIAN;
    c.pose_goal = dds::to_wire(world_base * base_tool);
    c.speed_scale = 0.5;
    c.timeout_s = 30.0;
    if (motion.write(c) != DDS_RETCODE_OK) return false;
    if (!cell_.wait_until([&] { return motions.count(id) && motions[id] > rigger_robot_MOTION_EXECUTING; }, 40s))
      return false;
    tool.reset();
    return motions[id] == rigger_robot_MOTION_SUCCEEDED && cell_.wait_until([&] { return tool && !moving; }, 10s);
  };

  const std::optional<double> before_mm = track_part();
  ASSERT_TRUE(before_mm.has_value()) << "the tracker did not see the part before the calibration";
  EXPECT_GT(*before_mm, 5.0) << "the camera's error does not show in the tracked part";

  // The integrator holds the board up to the camera (the arm's ready orientation turned 23° up, 25 cm to its
  // left, as CalibrationBoardProcessTest does), then calibrates.
  Eigen::Isometry3d show = Eigen::Isometry3d::Identity();
  show.linear() = Eigen::AngleAxisd(-23.0 * M_PI / 180.0, Eigen::Vector3d::UnitY()) * ready.linear();
  show.translation() = Eigen::Vector3d(0.65, 0.25, 0.46);
  ASSERT_TRUE(move_tool("show-board", show)) << cell_.logs();
  const CtlResult ctl = run_riggerctl(cell_, "riggerctl-calibrate", {"calibrate", "camera", "--timeout", "300"}, 320s);
  std::printf("--- riggerctl calibrate camera (exit %d):\n%s", ctl.code(), ctl.output.c_str());
  ASSERT_EQ(ctl.code(), 0) << cell_.logs();
  ASSERT_TRUE(cell_.wait_until([&] { return calibrated.has_value(); }, 10s)) << "no revision from CalibrateCamera";
  const std::string taken = "cell revision " + std::to_string(calibrated->cell_revision);
  for (const char* service : {"cell_sim", "vision_tracker"}) {
    ASSERT_TRUE(service_detail_says(cell_, service, taken, 20s)) << service << " did not follow " << taken;
    cell_.directory().update();
    EXPECT_EQ(cell_.directory().services().at(service).detail.find("refused"), std::string::npos)
        << service << ": " << cell_.directory().services().at(service).detail;
  }

  const cell::CellFile revised = cell::parse_cell_file(calibrated->cell_json, "the calibrated revision");
  const Eigen::Isometry3d off = world_camera_true.inverse() * revised.pose_root_entity("camera");
  const json record = json::parse(calibrated->cell_json);
  json calibration = json::object();
  for (const json& e : record["entities"])
    if (e["id"] == "camera" && e.contains("attributes"))
      calibration = e["attributes"].value("calibration", json::object());
  std::printf(
      "camera drawn %.2f mm / %.3f deg off the truth; calibrated %.2f mm / %.3f deg off (%zu poses, residual "
      "%.3f mm / %.4f deg rms)\n",
      (world_camera_true.inverse() * world_camera_drawn).translation().norm() * 1e3,
      angle_deg((world_camera_true.inverse() * world_camera_drawn).linear()), off.translation().norm() * 1e3,
      angle_deg(off.linear()), calibration.value("poses", json::array()).size(),
      calibration.value("residual_rms_mm", -1.0), calibration.value("residual_rms_deg", -1.0));
  EXPECT_LT(off.translation().norm() * 1e3, 3.0);
  EXPECT_LT(angle_deg(off.linear()), 0.2);

  ASSERT_TRUE(move_tool("back-to-ready", ready)) << cell_.logs();
  const std::optional<double> after_mm = track_part();
  ASSERT_TRUE(after_mm.has_value()) << "the tracker did not see the part after the calibration";
  std::printf("part tracked %.2f mm from the truth before the calibration, %.2f mm after\n", *before_mm, *after_mm);
  EXPECT_LT(*after_mm, 5.0);
}

}  // namespace
}  // namespace rigger::testing
