// Closed-loop tests of the three laws together on the small plant of crane_cell_plant.hpp: the
// shipped configuration, the simulated cell's geometry, a 500 Hz robot loop, a 50 Hz crane loop and a
// 30 Hz camera. (The MuJoCo closed loop over DDS comes with the service node.)

#include <cmath>
#include <cstdio>
#include <limits>
#include <optional>

#include <gtest/gtest.h>

#include "control_config.hpp"
#include "crane_cell_plant.hpp"

namespace rigger::control {
namespace {

using test::CraneCellPlant;
using test::CraneCellPlantConfig;

constexpr double kDeg = kPi / 180.0;
// The interaction force the collaboration must stay below (a ForceMonitor threshold a recipe would
// set). Accelerating the 40 kg load at the robot's 0.5 m/s^2 limit alone takes 20 N.
constexpr double kInteractionForceLimitN = 30.0;

ControlConfig shipped_config(const CraneCellPlantConfig& plant) {
  ControlConfig c = load_control_config_file(std::string(RIGGER_SOURCE_DIR) +
                                             "/services/admittance_control/config/admittance_control.json");
  // The simulated gripper's weight (the cell file does not state one yet; the plant's is used).
  c.robot.tool = plant.tool;
  c.robot.tcp_in_sensor_m = plant.tcp_in_sensor_m;
  return c;
}

// The robot law, the crane law and the plant stepped together; the caller supplies the reference.
class CollaborativeLoop {
 public:
  CollaborativeLoop(const CraneCellPlantConfig& plant_config, const ControlConfig& config)
      : plant_(plant_config, 7),
        robot_(config.robot),
        crane_(config.crane),
        dt_(1.0 / config.robot_rate_hz),
        crane_every_(static_cast<int>(std::lround(config.robot_rate_hz / config.crane_rate_hz))) {
    robot_.set_mode(AdmittanceMode::kRobotAndCrane);
    crane_.set_enabled(true);
  }

  /// One robot cycle (and a crane cycle every crane_every_). Returns the robot law's output.
  AdmittanceOutput step(const ReferenceInput& reference, const Eigen::Vector3d& push_on_load_n,
                        bool give_rope_offset) {
    const AdmittanceOutput out = robot_.step(Seconds(dt_), plant_.wrench_sample(),
                                             plant_.orientation_world_sensor(), reference);
    if (cycle_ % crane_every_ == 0) {
      CraneInput in;
      in.force_on_robot_world_n = out.wrench_base.force_n;  // the robot base is aligned with the world
      in.force_age = Seconds(0.001);
      in.robot_velocity_world_mps = out.twist.linear_mps;
      if (give_rope_offset) in.rope_offset_world_m = plant_.rope_offset_world();
      crane_output_ = crane_.step(Seconds(dt_ * crane_every_), in);
    }
    ++cycle_;
    plant_.step(dt_, out.twist, crane_output_.velocity_world_mps, push_on_load_n);
    return out;
  }

  CraneCellPlant& plant() { return plant_; }
  RobotAdmittance& robot() { return robot_; }
  const CraneOutput& crane_output() const { return crane_output_; }
  double dt() const { return dt_; }

 private:
  CraneCellPlant plant_;
  RobotAdmittance robot_;
  CraneAdmittance crane_;
  double dt_;
  int crane_every_;
  long cycle_ = 0;
  CraneOutput crane_output_;
};

double horizontal(const Eigen::Vector3d& v) { return std::hypot(v.x(), v.y()); }

TEST(ClosedLoop, VisualServoBringsTheLoadToItsInsertionPoseFromHalfAMetre) {
  const CraneCellPlantConfig plant_config = test::simulated_cell_plant_config(8.0);
  ControlConfig config = shipped_config(plant_config);
  config.crane.selected_axes = {true, true, true};  // the insertion goes down: the hoist follows
  CollaborativeLoop loop(plant_config, config);
  loop.robot().set_reference_source(ReferenceSource::kVisualServo);
  VisualServoConfig servo_config = config.visual_servo;
  servo_config.pose_target_load_insertion = plant_config.pose_target_load_insertion;
  const VisualServo servo(servo_config);

  const Eigen::Isometry3d goal = servo.goal(loop.plant().pose_world_target());
  const PoseError start = compute_pose_error(loop.plant().pose_world_load(), goal);
  ASSERT_GE(start.distance_m, 0.5);

  ReferenceInput reference{ReferenceSource::kVisualServo, Twist{}, ControlFrame::kBase,
                           Seconds(std::numeric_limits<double>::infinity())};
  double reference_time_s = -1e9;
  ServoOutput servo_output;
  double converged_at_s = -1.0;
  double max_horizontal_force_n = 0.0;
  double max_force_n = 0.0;
  while (loop.plant().time_s() < 60.0) {
    if (auto observation = loop.plant().take_observation()) {
      servo_output = servo.update(observation->first, observation->second);
      ASSERT_TRUE(servo_output.tracking()) << to_string(servo_output.stop_reason);
      // The servo's twist is the load's; the robot commands its TCP, rigidly attached to it.
      reference.twist = shift_twist(servo_output.twist_world, loop.plant().pose_world_tcp().translation() -
                                                                  observation->first.pose_world.translation());
      reference_time_s = loop.plant().time_s();
      if (servo_output.converged && converged_at_s < 0.0) converged_at_s = loop.plant().time_s();
    }
    reference.age = Seconds(loop.plant().time_s() - reference_time_s);
    const AdmittanceOutput out = loop.step(reference, Eigen::Vector3d::Zero(), false);
    ASSERT_EQ(out.status.state, AdmittanceState::kActive) << to_string(out.status.fault);
    ASSERT_EQ(loop.crane_output().status.state, CraneState::kActive) << to_string(loop.crane_output().status.fault);
    max_horizontal_force_n = std::max(max_horizontal_force_n, horizontal(loop.plant().force_on_robot_world()));
    max_force_n = std::max(max_force_n, loop.plant().force_on_robot_world().norm());
    if (converged_at_s >= 0.0 && loop.plant().time_s() > converged_at_s + 2.0) break;
  }
  const PoseError end = compute_pose_error(loop.plant().pose_world_load(), goal);
  std::printf("[ servo    ] from %.3f m / %.2f deg: converged after %.2f s; 2 s later %.2f mm / %.3f deg "
              "(ground truth); max interaction force %.1f N (horizontal %.1f N)\n",
              start.distance_m, start.angle_rad / kDeg, converged_at_s, end.distance_m * 1e3, end.angle_rad / kDeg,
              max_force_n, max_horizontal_force_n);
  EXPECT_GE(converged_at_s, 0.0) << "never reported convergence";
  EXPECT_TRUE(servo_output.converged);
  EXPECT_LE(end.distance_m, 0.005);
  EXPECT_LE(end.angle_rad, 1.0 * kDeg);
  EXPECT_LT(max_force_n, kInteractionForceLimitN);
}

TEST(ClosedLoop, JoystickMovesRobotAndCraneTogether) {
  const CraneCellPlantConfig plant_config = test::simulated_cell_plant_config(0.0);
  CollaborativeLoop loop(plant_config, shipped_config(plant_config));
  loop.robot().set_reference_source(ReferenceSource::kJoystick);
  ReferenceInput joystick{ReferenceSource::kJoystick, Twist{Eigen::Vector3d(0.1, -0.05, 0.0), Eigen::Vector3d::Zero()},
                          ControlFrame::kBase, Seconds(0.01)};
  const Eigen::Vector3d start = loop.plant().pose_world_tcp().translation();
  double max_horizontal_force_n = 0.0;
  double max_rope_offset_m = 0.0;
  AdmittanceOutput out;
  while (loop.plant().time_s() < 8.0) {
    out = loop.step(joystick, Eigen::Vector3d::Zero(), false);
    max_horizontal_force_n = std::max(max_horizontal_force_n, horizontal(loop.plant().force_on_robot_world()));
    max_rope_offset_m = std::max(max_rope_offset_m, horizontal(loop.plant().rope_offset_world()));
  }
  const Eigen::Vector3d crane_velocity = loop.plant().crane_velocity_world();
  const Eigen::Vector3d moved = loop.plant().pose_world_tcp().translation() - start;
  std::printf("[ joystick ] after 8 s: robot (%.3f, %.3f) m/s, crane (%.3f, %.3f) m/s, moved %.3f m; max "
              "horizontal force %.1f N, max rope offset %.1f mm\n",
              out.twist.linear_mps.x(), out.twist.linear_mps.y(), crane_velocity.x(), crane_velocity.y(),
              horizontal(moved), max_horizontal_force_n, max_rope_offset_m * 1e3);
  EXPECT_NEAR(out.twist.linear_mps.x(), 0.1, 0.01);
  EXPECT_NEAR(out.twist.linear_mps.y(), -0.05, 0.005);
  EXPECT_NEAR(crane_velocity.x(), 0.1, 0.01);
  EXPECT_NEAR(crane_velocity.y(), -0.05, 0.005);
  EXPECT_LT(max_horizontal_force_n, kInteractionForceLimitN);
  EXPECT_LT(max_rope_offset_m, 0.05);
  // Let go of the stick: both come to rest with the rope hanging (nearly) straight.
  joystick.twist = Twist{};
  while (loop.plant().time_s() < 20.0) out = loop.step(joystick, Eigen::Vector3d::Zero(), false);
  EXPECT_LT(out.twist.linear_mps.norm(), 0.002);
  EXPECT_LT(loop.plant().crane_velocity_world().norm(), 0.002);
  EXPECT_LT(horizontal(loop.plant().rope_offset_world()), 0.015);  // the crane's 1 N deadband: 8 mm
}

TEST(ClosedLoop, APushOnTheLoadMovesRobotAndCraneTogetherWithRopeOffsetFeedback) {
  const CraneCellPlantConfig plant_config = test::simulated_cell_plant_config(0.0);
  ControlConfig config = shipped_config(plant_config);
  config.crane.rope_offset_gain_per_s = 0.5;
  CollaborativeLoop loop(plant_config, config);
  const Eigen::Vector3d push(20.0, 0.0, 0.0);
  double max_horizontal_force_n = 0.0;
  AdmittanceOutput out;
  while (loop.plant().time_s() < 15.0) {
    out = loop.step(ReferenceInput{}, push, true);
    max_horizontal_force_n = std::max(max_horizontal_force_n, horizontal(loop.plant().force_on_robot_world()));
  }
  const double crane_vx = loop.plant().crane_velocity_world().x();
  std::printf("[ push     ] 20 N on the load with offset feedback, after 15 s: robot %.3f m/s, crane %.3f m/s, "
              "rope offset %.1f mm, max horizontal force %.1f N\n",
              out.twist.linear_mps.x(), crane_vx, loop.plant().rope_offset_world().x() * 1e3, max_horizontal_force_n);
  EXPECT_GT(out.twist.linear_mps.x(), 0.05);
  EXPECT_NEAR(crane_vx, out.twist.linear_mps.x(), 0.005);  // together
  EXPECT_LT(max_horizontal_force_n, 20.0 + 1.0);           // never more than the push
}

TEST(ClosedLoop, WithoutOffsetFeedbackAPushOnTheLoadComesToRestAgainstTheRope) {
  // The documented limit of a wrist-force-only crane law (docs/control.md): the wrist cannot tell a
  // person's push from the rope's pull, so the load settles where the tilted rope balances the push,
  // F / (m g / L) from the hook.
  const CraneCellPlantConfig plant_config = test::simulated_cell_plant_config(0.0);
  CollaborativeLoop loop(plant_config, shipped_config(plant_config));
  const Eigen::Vector3d push(20.0, 0.0, 0.0);
  AdmittanceOutput out;
  while (loop.plant().time_s() < 40.0) out = loop.step(ReferenceInput{}, push, false);
  const double rope_m = plant_config.rail_height_m - (plant_config.pose_world_load * plant_config.rope_attachment_load_m).z();
  const double balance_m = push.x() / (plant_config.load_mass_kg * 9.81 / rope_m);
  std::printf("[ push     ] 20 N without offset feedback, after 40 s: robot %.4f m/s, rope offset %.1f mm "
              "(balance %.1f mm)\n",
              out.twist.linear_mps.x(), loop.plant().rope_offset_world().x() * 1e3, balance_m * 1e3);
  EXPECT_LT(std::abs(out.twist.linear_mps.x()), 0.005);
  EXPECT_NEAR(loop.plant().rope_offset_world().x(), balance_m, 0.03);
}

}  // namespace
}  // namespace rigger::control
