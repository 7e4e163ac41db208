#pragma once
/// @file
/// Value types shared by the control laws of `rigger::control` (robot admittance, crane admittance,
/// position-based visual servo): wrenches, twists, per-axis vectors, and the frame conventions.
///
/// Conventions:
/// - Per-axis 6-vectors are ordered (x, y, z, rx, ry, rz): linear axes first (m, m/s, N), then the
///   rotations about x, y, z (rad, rad/s, N m).
/// - `R_a_b` maps vectors expressed in frame b into frame a (the orientation of b in a).
/// - A wrench is given about a reference point; a twist's linear part is the velocity of a reference
///   point. Moving that point is `shift_wrench` / `shift_twist`.
/// Pure C++ and Eigen: no DDS, no logging.

#include <chrono>
#include <optional>
#include <string>

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace rigger::control {

/// The answer to a runtime request (new gains, new limits): refused requests change nothing.
struct RequestResult {
  bool accepted = true;
  std::string reason;  ///< why it was refused; empty when accepted
};

/// A rule a configuration breaks: the JSON pointer of the field (relative to the configuration
/// object, using the configuration file's key names) and what was expected there.
struct ConfigProblem {
  std::string pointer;
  std::string problem;
};

/// Durations in (fractional) seconds; identical to `rigger::Seconds`.
using Seconds = std::chrono::duration<double>;
/// Per-axis vector (x, y, z, rx, ry, rz).
using Vector6d = Eigen::Matrix<double, 6, 1>;

/// A force (N) and a torque (N m) about a reference point, both in one frame.
struct Wrench {
  Eigen::Vector3d force_n = Eigen::Vector3d::Zero();
  Eigen::Vector3d torque_nm = Eigen::Vector3d::Zero();

  /// (fx, fy, fz, tx, ty, tz).
  Vector6d stacked() const;
  /// Inverse of stacked().
  static Wrench from_stacked(const Vector6d& values);
  /// True when every component is a finite number.
  bool all_finite() const;
};

/// A linear velocity (m/s) of a reference point and an angular velocity (rad/s), both in one frame.
struct Twist {
  Eigen::Vector3d linear_mps = Eigen::Vector3d::Zero();
  Eigen::Vector3d angular_radps = Eigen::Vector3d::Zero();

  /// (vx, vy, vz, wx, wy, wz).
  Vector6d stacked() const;
  /// Inverse of stacked().
  static Twist from_stacked(const Vector6d& values);
  /// True when every component is a finite number.
  bool all_finite() const;
};

/// The same wrench expressed in frame a: `R_a_b` applied to force and torque of `wrench_b`.
Wrench rotate(const Eigen::Matrix3d& R_a_b, const Wrench& wrench_b);
/// The same twist expressed in frame a: `R_a_b` applied to both parts of `twist_b`.
Twist rotate(const Eigen::Matrix3d& R_a_b, const Twist& twist_b);

/// The wrench about point B given the wrench about point A: force unchanged, torque
/// tau_B = tau_A - r x f, with `r_a_b_m` the vector from A to B (same frame as the wrench, m).
Wrench shift_wrench(const Wrench& wrench_about_a, const Eigen::Vector3d& r_a_b_m);
/// The twist of a rigid body at point B given its twist at point A: v_B = v_A + w x r, with
/// `r_a_b_m` the vector from A to B (same frame as the twist, m).
Twist shift_twist(const Twist& twist_at_a, const Eigen::Vector3d& r_a_b_m);

}  // namespace rigger::control
