#include "rigger/sim/crane_drive.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

namespace rigger::sim {
namespace {

// A frictionless cart of 1000 kg under the drive, with an optional external force and a motor
// force limit: the drive's output acceleration is applied through the mass, like the physics does.
struct Cart {
  double position = 0.0;
  double velocity = 0.0;

  void step(TravelDrive& drive, double dt, double external_force = 0.0, double force_limit = 1e9) {
    const double mass = 1000.0;
    const double force =
        std::clamp(mass * drive.update(position, velocity, dt), -force_limit, force_limit);
    velocity += (force + external_force) / mass * dt;
    position += velocity * dt;
  }
};

TravelDrive::Params drive_params() {
  TravelDrive::Params params;
  params.position_min_m = 0.0;
  params.position_max_m = 8.0;
  return params;
}

TEST(TravelDrive, TracksTheVelocitySetpoint) {
  TravelDrive drive(drive_params());
  Cart cart;
  cart.position = 1.0;
  drive.reset(1.0);
  drive.set_velocity_setpoint(0.4);
  for (int i = 0; i < 2000; ++i) {
    cart.step(drive, 0.001);
  }
  EXPECT_NEAR(cart.velocity, 0.4, 1e-3);
  EXPECT_NEAR(drive.ramped_velocity_mps(), 0.4, 1e-12);
  // 2 s at 0.4 m/s minus the drive's ramp (0.4 m/s at 3 m/s^2: 0.027 m lost).
  EXPECT_NEAR(cart.position, 1.0 + 0.8 - 0.4 * 0.4 / (2 * 3.0), 0.005);
}

TEST(TravelDrive, HoldsPositionAgainstAPushAtZeroSetpoint) {
  TravelDrive drive(drive_params());
  Cart cart;
  cart.position = 2.0;
  drive.reset(2.0);
  for (int i = 0; i < 5000; ++i) {
    cart.step(drive, 0.001, 500.0);
  }
  EXPECT_NEAR(cart.position, 2.0, 0.005);
  EXPECT_NEAR(cart.velocity, 0.0, 1e-3);
}

TEST(TravelDrive, ReferenceStopsAtTheEndStop) {
  TravelDrive drive(drive_params());
  Cart cart;
  cart.position = 7.9;
  drive.reset(7.9);
  drive.set_velocity_setpoint(0.5);
  for (int i = 0; i < 3000; ++i) {
    cart.step(drive, 0.001);
  }
  EXPECT_LE(drive.reference_position_m(), 8.0);
  EXPECT_NEAR(cart.position, 8.0, 0.005);
  EXPECT_NEAR(cart.velocity, 0.0, 1e-3);
}

TEST(TravelDrive, AbruptStopRampsDownWithoutComingBack) {
  // The drive's ramp matches what its force limit can do (2 m/s^2 on the 1000 kg cart).
  TravelDrive::Params params = drive_params();
  params.max_accel_mps2 = 1.6;
  TravelDrive drive(params);
  Cart cart;
  cart.position = 1.0;
  drive.reset(1.0);
  drive.set_velocity_setpoint(0.5);
  for (int i = 0; i < 2000; ++i) {
    cart.step(drive, 0.001, 0.0, 2000.0);
  }
  drive.set_velocity_setpoint(0.0);
  int steps = 0;
  while (std::abs(cart.velocity) > 1e-3 && steps < 5000) {
    cart.step(drive, 0.001, 0.0, 2000.0);
    ++steps;
  }
  // 0.5 m/s at the 1.6 m/s^2 ramp: about 0.31 s, not an instant stop.
  EXPECT_GT(steps, 250);
  EXPECT_LT(steps, 450);
  // It stays where it stopped: no creeping back to where the stop was commanded.
  const double stopped_at = cart.position;
  double slowest = 0.0;
  for (int i = 0; i < 2000; ++i) {
    cart.step(drive, 0.001, 0.0, 2000.0);
    slowest = std::min(slowest, cart.velocity);
  }
  EXPECT_GT(slowest, -2e-3);
  EXPECT_NEAR(cart.position, stopped_at, 2e-3);
}

TEST(TravelDrive, NonPositiveTimeStepDoesNothing) {
  TravelDrive drive(drive_params());
  drive.reset(3.0);
  drive.set_velocity_setpoint(1.0);
  EXPECT_DOUBLE_EQ(drive.update(3.0, 0.0, 0.0), 0.0);
  EXPECT_DOUBLE_EQ(drive.reference_position_m(), 3.0);
}

TEST(HoistDrum, RampsToTheSetpointAndStopsAtTheRangeEnds) {
  HoistDrum::Params params;
  params.payout_min_m = 0.5;
  params.payout_max_m = 3.8;
  params.max_accel_mps2 = 2.0;
  HoistDrum drum(params);
  drum.reset(1.0);
  drum.set_velocity_setpoint(0.2);
  drum.update(0.001);
  EXPECT_NEAR(drum.payout_rate_mps(), 0.002, 1e-12);  // acceleration limited
  for (int i = 0; i < 1000; ++i) {
    drum.update(0.001);
  }
  EXPECT_NEAR(drum.payout_rate_mps(), 0.2, 1e-6);
  drum.set_velocity_setpoint(-0.2);
  for (int i = 0; i < 10000; ++i) {
    drum.update(0.001);
  }
  EXPECT_DOUBLE_EQ(drum.payout_m(), 0.5);
  EXPECT_DOUBLE_EQ(drum.payout_rate_mps(), 0.0);
  drum.reset(10.0);
  EXPECT_DOUBLE_EQ(drum.payout_m(), 3.8);
}

TEST(RopeTension, PullsWhenStretchedAndNeverPushes) {
  RopeParams rope;
  rope.stiffness_n_per_m = 2e5;
  rope.damping_n_s_per_m = 2000;
  EXPECT_NEAR(rope_tension_n(3.002, 0.0, 3.0, 0.0, rope), 400.0, 1e-9);
  EXPECT_DOUBLE_EQ(rope_tension_n(2.9, 0.0, 3.0, 0.0, rope), 0.0);  // slack
  // Stretched but the hook springs back fast: the rope goes slack instead of pushing.
  EXPECT_DOUBLE_EQ(rope_tension_n(3.001, -1.0, 3.0, 0.0, rope), 0.0);
  // Damping acts on the stretch rate, not the hook speed alone.
  EXPECT_NEAR(rope_tension_n(3.001, 0.2, 3.0, 0.2, rope), 200.0, 1e-9);
}

}  // namespace
}  // namespace rigger::sim
