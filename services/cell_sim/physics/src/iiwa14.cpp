#include "rigger/sim/iiwa14.hpp"

#include <cmath>

namespace rigger::sim::iiwa14 {
namespace {
constexpr double kDegToRad = M_PI / 180.0;
}  // namespace

JointVector position_limits_rad() {
  return (JointVector() << 170, 120, 170, 120, 170, 120, 175).finished() * kDegToRad;
}

JointVector speed_limits_rad_per_s() {
  return (JointVector() << 85, 85, 100, 75, 130, 135, 135).finished() * kDegToRad;
}

JointVector torque_limits_nm() {
  return (JointVector() << 320, 320, 176, 176, 110, 40, 40).finished();
}

JointVector acceleration_limits_rad_per_s2() {
  return (JointVector() << 5, 5, 6, 5, 8, 8, 8).finished();
}

}  // namespace rigger::sim::iiwa14
