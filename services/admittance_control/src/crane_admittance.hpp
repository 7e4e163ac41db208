#pragma once
/// @file
/// The crane's admittance law: the interaction force between robot and load, measured at the robot's
/// wrist and expressed in the world frame, becomes a crane velocity (bridge, trolley and optionally
/// hoist), so that the crane carries the load where the robot guides it. Per world axis i:
///
///     M_i * du_i/dt + D_i * u_i = deadband(lowpass(f_i))      f = -(force the load exerts on the robot)
///     v_i = u_i + alpha * v_robot_i + k_offset * offset_i      (then speed and acceleration limits)
///
/// f is the force the robot applies to the load: when the robot pulls the load towards +x, the load
/// pulls back on the wrist (-x) and the crane moves +x. The feed-forward alpha * v_robot makes the
/// crane move with the robot's commanded motion; the admittance term u removes what the feed-forward
/// misses (the rope's horizontal pull grows with the offset between load and hook), and the
/// optional offset term uses a measured load-to-hook offset directly. docs/control.md derives the
/// split and its steady states.
///
/// World frame: z up. Crane axes: bridge = world x, trolley = world y, hoist = world z (rope length
/// is the other way round: to_crane_axes()).
/// Pure C++ and Eigen: no DDS, no logging. Not thread-safe: one thread calls step() and the setters.
/// The constructor throws rigger::ConfigError; nothing else throws.

#include <array>
#include <optional>
#include <string_view>

#include <Eigen/Core>

#include "control_math.hpp"
#include "control_types.hpp"

namespace rigger::control {

/// Virtual dynamics per world axis (x = bridge, y = trolley, z = hoist).
struct CraneGains {
  Eigen::Vector3d mass_kg{150.0, 150.0, 150.0};             ///< > 0
  Eigen::Vector3d damping_ns_per_m{300.0, 300.0, 600.0};    ///< > 0
};

/// The first rule `gains` break (pointer relative to the gains object), if any.
std::optional<ConfigProblem> find_problem(const CraneGains& gains);

/// Setup-time configuration of CraneAdmittance. Field names follow the configuration file's keys.
struct CraneAdmittanceConfig {
  CraneGains gains;
  /// World axes the crane moves on: bridge (x), trolley (y), hoist (z, off by default).
  std::array<bool, 3> selected_axes{true, true, false};
  /// Force deadband per axis, N, >= 0. Keep it below the robot law's linear deadband so that the
  /// crane, not the robot, takes up any residual pull (docs/control.md, tuning).
  Eigen::Vector3d deadband_n{1.0, 1.0, 1.0};
  /// First-order low-pass on the force, Hz (0: off); below half the crane loop's rate.
  double force_filter_cutoff_hz = 2.0;
  /// Per-axis speed limit, m/s, >= 0 (the cell's crane: 0.5, 0.5, 0.2); each axis on its own.
  Eigen::Vector3d max_speed_mps{0.5, 0.5, 0.2};
  /// Per-axis acceleration limit, m/s^2, > 0 (the cell's crane: 0.5, 0.5, 0.3); each axis on its own.
  Eigen::Vector3d max_acceleration_mps2{0.5, 0.5, 0.3};
  /// Per-axis deceleration of a stop (disabled: the ramp to zero), m/s^2, > 0; never slower than
  /// max_acceleration_mps2. The PLC ramps too: it must brake at least as hard (its stop_decel_mps2).
  Eigen::Vector3d stop_deceleration_mps2{0.5, 0.5, 0.3};
  /// Share of the robot's commanded TCP velocity fed forward to the crane, in [0, 1].
  double robot_velocity_feedforward = 1.0;
  /// Gain on a measured horizontal load-to-hook offset, 1/s, >= 0 (0: not used).
  double rope_offset_gain_per_s = 0.0;
  /// A force older than this: zero output and fault FORCE_STALE.
  Seconds force_timeout{0.1};
  /// A time step outside (0, max_time_step] is refused (fault TIME_STEP_INVALID).
  Seconds max_time_step{0.2};
  /// Above this force norm (N) the input is a fault, never a command.
  double max_plausible_force_n = 2000.0;
  /// Time over which a gain change is blended in.
  Seconds gain_transition_time{1.0};
};

/// The first rule `config` breaks (pointer relative to the configuration object), if any.
std::optional<ConfigProblem> find_problem(const CraneAdmittanceConfig& config);

/// Inputs of one crane cycle.
struct CraneInput {
  /// Force the load exerts on the robot at the wrist (tool weight removed), world frame, N: e.g.
  /// AdmittanceOutput::wrench_base.force_n rotated from the robot base into the world.
  Eigen::Vector3d force_on_robot_world_n = Eigen::Vector3d::Zero();
  /// Now minus the force's measurement stamp.
  Seconds force_age{0.0};
  /// The robot's commanded TCP linear velocity, world frame, m/s (feed-forward).
  Eigen::Vector3d robot_velocity_world_mps = Eigen::Vector3d::Zero();
  /// Rope attachment point on the load minus the point below the hook, world frame, m (only x and
  /// y are used), when known (crane state and load pose); std::nullopt otherwise.
  std::optional<Eigen::Vector3d> rope_offset_world_m;
};

enum class CraneState { kDisabled, kStopping, kActive, kFault };
/// Why the crane output is zero. Non-finite or implausible input latches until set_enabled(true).
enum class CraneFault {
  kNone,
  kForceStale,        ///< FORCE_STALE
  kForceNotFinite,    ///< FORCE_NOT_FINITE (latched)
  kForceImplausible,  ///< FORCE_IMPLAUSIBLE (latched)
  kInputInvalid,      ///< INPUT_INVALID: non-finite feed-forward velocity or offset (latched)
  kTimeStepInvalid,   ///< TIME_STEP_INVALID
};

/// "DISABLED", "STOPPING", "ACTIVE", "FAULT".
std::string_view to_string(CraneState state);
/// The fault code, e.g. "FORCE_STALE" ("NONE" for kNone).
std::string_view to_string(CraneFault fault);

struct CraneStatus {
  CraneState state = CraneState::kDisabled;
  CraneFault fault = CraneFault::kNone;
  bool fault_latched = false;
  bool velocity_limited = false;
  bool acceleration_limited = false;
  bool gains_blending = false;
};

struct CraneOutput {
  /// Commanded crane velocity, world frame (x bridge, y trolley, z hoist up), m/s; zero on a fault.
  Eigen::Vector3d velocity_world_mps = Eigen::Vector3d::Zero();
  CraneStatus status;
  /// The filtered, deadbanded interaction force that drove the law (robot on load), world, N.
  Eigen::Vector3d force_applied_n = Eigen::Vector3d::Zero();
};

/// A world-frame crane velocity in the crane interface's axis order and signs (idl/crane.idl):
/// bridge = x, trolley = y, hoist = rope length rate (positive lowers, so -z).
std::array<double, 3> to_crane_axes(const Eigen::Vector3d& velocity_world_mps);

/// The crane admittance law (see the file comment).
class CraneAdmittance {
 public:
  /// @throws rigger::ConfigError (file "CraneAdmittanceConfig") when `config` breaks a rule.
  explicit CraneAdmittance(CraneAdmittanceConfig config);

  /// Enables or disables the law; either acknowledges a latched fault. Disabling a moving crane
  /// ramps its command to zero at the acceleration limits.
  void set_enabled(bool enabled);
  bool enabled() const { return enabled_; }

  /// Blends new gains in over gain_transition_time; refused (nothing changes) when invalid.
  RequestResult set_gains(const CraneGains& gains);
  /// The gains in effect at the last step.
  CraneGains current_gains() const;

  /// One crane cycle of length `dt`; never throws.
  CraneOutput step(Seconds dt, const CraneInput& input);

  const CraneAdmittanceConfig& config() const { return config_; }

 private:
  using GainMatrix = Eigen::Matrix<double, 3, 2>;  // columns: mass, damping

  CraneOutput fault_output(CraneFault fault, bool latch);
  void reset_state();

  CraneAdmittanceConfig config_;
  bool enabled_ = false;
  CraneFault latched_fault_ = CraneFault::kNone;
  GainBlend<GainMatrix> gains_;
  std::array<CachedAxisDiscretisation, 3> discretisation_;
  Eigen::Vector3d admittance_velocity_ = Eigen::Vector3d::Zero();  // u
  Eigen::Vector3d filtered_force_ = Eigen::Vector3d::Zero();
  Eigen::Vector3d last_output_ = Eigen::Vector3d::Zero();
};

}  // namespace rigger::control
