#pragma once
// Published limits of the KUKA LBR iiwa 14 R820 (KUKA's specification sheet), plus the motion
// limits this simulation chooses where KUKA publishes none.

#include "rigger/sim/physics_types.hpp"

namespace rigger::sim::iiwa14 {

/// Axis range, symmetric about zero: +-170, +-120, +-170, +-120, +-170, +-120, +-175 deg.
JointVector position_limits_rad();

/// Maximum joint speeds: 85, 85, 100, 75, 130, 135, 135 deg/s.
JointVector speed_limits_rad_per_s();

/// Maximum joint torques: 320, 320, 176, 176, 110, 40, 40 N m.
JointVector torque_limits_nm();

/// Joint accelerations the simulated controller allows (not published by KUKA; chosen so that a
/// joint reaches full speed in about 0.3 s).
JointVector acceleration_limits_rad_per_s2();

/// Link lengths along the arm (m): base to A2, A2 to A4, A4 to A6, A6 to flange.
inline constexpr double kBaseToA2M = 0.36;
inline constexpr double kA2ToA4M = 0.42;
inline constexpr double kA4ToA6M = 0.40;
inline constexpr double kA6ToFlangeM = 0.126;

}  // namespace rigger::sim::iiwa14
