// Cost of one control cycle of each law (not a test; run on demand). The control loop's wake-up
// lateness is measured later, with the service's real loop, against a bare timed loop.

#include <benchmark/benchmark.h>

#include "crane_admittance.hpp"
#include "robot_admittance.hpp"
#include "visual_servo.hpp"

namespace rigger::control {
namespace {

const Seconds kDt{0.002};

WrenchSample reading(double t) {
  WrenchSample s;
  s.wrench_sensor.force_n = Eigen::Vector3d(10.0 + std::sin(t), -5.0, 20.0);
  s.wrench_sensor.torque_nm = Eigen::Vector3d(0.3, -0.2, 0.1);
  s.age = Seconds(0.001);
  return s;
}

// Steady state: constant gains and period, so the discretisation cache holds.
void BM_RobotAdmittanceStep(benchmark::State& state) {
  RobotAdmittanceConfig config;
  config.tool = ToolModel{2.5, Eigen::Vector3d(0.0, 0.0, 0.06)};
  RobotAdmittance law(config);
  law.set_mode(AdmittanceMode::kRobot);
  law.set_reference_source(ReferenceSource::kJoystick);
  const ReferenceInput joystick{ReferenceSource::kJoystick, Twist{Eigen::Vector3d(0.05, 0, 0), Eigen::Vector3d::Zero()},
                                ControlFrame::kBase, Seconds(0.01)};
  const Eigen::Quaterniond q(Eigen::AngleAxisd(0.3, Eigen::Vector3d(1, 1, 0).normalized()));
  double t = 0.0;
  for (auto _ : state) {
    benchmark::DoNotOptimize(law.step(kDt, reading(t), q, joystick));
    t += 0.002;
  }
}
BENCHMARK(BM_RobotAdmittanceStep);

// Worst case: a gain blend in progress, so every axis is re-discretised every cycle.
void BM_RobotAdmittanceStepWhileBlendingGains(benchmark::State& state) {
  RobotAdmittanceConfig config;
  config.gain_transition_time = Seconds(1e9);
  RobotAdmittance law(config);
  law.set_mode(AdmittanceMode::kRobot);
  AdmittanceGains stiffer = config.gains;
  stiffer.stiffness.setConstant(500.0);
  law.set_gains(stiffer);
  const Eigen::Quaterniond q = Eigen::Quaterniond::Identity();
  double t = 0.0;
  for (auto _ : state) {
    benchmark::DoNotOptimize(law.step(kDt, reading(t), q, ReferenceInput{}));
    t += 0.002;
  }
}
BENCHMARK(BM_RobotAdmittanceStepWhileBlendingGains);

void BM_CraneAdmittanceStep(benchmark::State& state) {
  CraneAdmittance law{CraneAdmittanceConfig{}};
  law.set_enabled(true);
  CraneInput in;
  in.force_on_robot_world_n = Eigen::Vector3d(-20.0, 5.0, 0.0);
  in.force_age = Seconds(0.001);
  in.robot_velocity_world_mps = Eigen::Vector3d(0.05, 0.0, 0.0);
  for (auto _ : state) benchmark::DoNotOptimize(law.step(Seconds(0.02), in));
}
BENCHMARK(BM_CraneAdmittanceStep);

void BM_VisualServoUpdate(benchmark::State& state) {
  const VisualServo servo{VisualServoConfig{}};
  Eigen::Isometry3d load = Eigen::Isometry3d::Identity();
  load.translation() = Eigen::Vector3d(3.55, 1.75, 1.2);
  load.linear() = Eigen::AngleAxisd(0.1, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  Eigen::Isometry3d target = Eigen::Isometry3d::Identity();
  target.translation() = Eigen::Vector3d(3.55, 2.25, 0.95);
  const TrackedPose l{load, 0.9, Seconds(0.05)}, t{target, 0.9, Seconds(0.05)};
  for (auto _ : state) benchmark::DoNotOptimize(servo.update(l, t));
}
BENCHMARK(BM_VisualServoUpdate);

}  // namespace
}  // namespace rigger::control

BENCHMARK_MAIN();
