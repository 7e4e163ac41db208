#pragma once
/// @file
/// The robot's admittance law: the contact wrench measured by the wrist force/torque sensor becomes a
/// Cartesian velocity command for the robot's tool centre point (TCP). Per axis of the control frame:
///
///     M * de/dt + D * e + K * x = f        with  e = v - v_ref,  dx/dt = e
///     v_cmd = v_ref + e                   (then velocity and acceleration limits)
///
/// where f is the measured wrench after tool-weight compensation, low-pass filtering and a deadband,
/// v_ref an optional reference twist (joystick or visual servo, low-pass filtered) added as a
/// velocity feed-forward, and x the deviation from the reference path (the spring's anchor moves
/// with the reference).
/// Integration is the exact zero-order-hold discretisation (see control_math.hpp); docs/control.md
/// explains parameters, frames, defaults and tuning.
///
/// Frames: the sensor frame S is the F/T sensor's; the TCP frame has the sensor's orientation and sits
/// at `tcp_in_sensor_m` in S; the base frame B is the robot's base, with gravity along
/// `gravity_base_mps2`. The control frame (where gains, limits, deadband, filter and the output twist
/// live) is B or the TCP frame.
///
/// Pure C++ and Eigen: no DDS, no logging. Not thread-safe: one thread calls step() and the setters.
/// The constructor throws rigger::ConfigError; nothing else throws.

#include <array>
#include <optional>
#include <string_view>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "control_math.hpp"
#include "control_types.hpp"

namespace rigger::control {

/// What the admittance service drives. OFF: nothing (a running robot is first brought to rest at
/// the acceleration limit). ROBOT: the robot law only. ROBOT_AND_CRANE: the robot law, and the crane
/// law (CraneAdmittance) follows the interaction force.
enum class AdmittanceMode { kOff, kRobot, kRobotAndCrane };
/// Where the reference twist comes from.
enum class ReferenceSource { kNone, kJoystick, kVisualServo };
/// A frame of the robot: its base, or the tool (TCP) frame (the sensor's orientation).
enum class ControlFrame { kBase, kTool };

/// "OFF", "ROBOT", "ROBOT_AND_CRANE".
std::string_view to_string(AdmittanceMode mode);
/// "NONE", "JOYSTICK", "VISUAL_SERVO".
std::string_view to_string(ReferenceSource source);
/// "base", "tool".
std::string_view to_string(ControlFrame frame);
/// Inverse of to_string(AdmittanceMode); std::nullopt for anything else.
std::optional<AdmittanceMode> admittance_mode_from_string(std::string_view text);
/// Inverse of to_string(ReferenceSource); std::nullopt for anything else.
std::optional<ReferenceSource> reference_source_from_string(std::string_view text);
/// Inverse of to_string(ControlFrame); std::nullopt for anything else.
std::optional<ControlFrame> control_frame_from_string(std::string_view text);

/// Virtual dynamics per axis (x, y, z, rx, ry, rz) of the control frame.
struct AdmittanceGains {
  /// Virtual mass, kg (linear axes) and kg m^2 (rotations), > 0.
  Vector6d mass = (Vector6d() << 10.0, 10.0, 10.0, 0.5, 0.5, 0.5).finished();
  /// Virtual damping, N s/m and N m s/rad, > 0: set explicitly so that free guiding (K = 0) is damped.
  Vector6d damping = (Vector6d() << 100.0, 100.0, 100.0, 10.0, 10.0, 10.0).finished();
  /// Virtual stiffness, N/m and N m/rad, >= 0 (0: free guiding).
  Vector6d stiffness = Vector6d::Zero();
  friend bool operator==(const AdmittanceGains& a, const AdmittanceGains& b) {
    return a.mass == b.mass && a.damping == b.damping && a.stiffness == b.stiffness;
  }
  friend bool operator!=(const AdmittanceGains& a, const AdmittanceGains& b) { return !(a == b); }
};

/// The first rule `gains` break (pointer relative to the gains object, e.g. "/damping/2"), if any.
std::optional<ConfigProblem> find_problem(const AdmittanceGains& gains);

/// Velocity and acceleration limits of the output twist, per axis of the control frame.
struct MotionLimits {
  /// m/s and rad/s, >= 0 (0 locks the axis).
  Vector6d max_velocity = (Vector6d() << 0.25, 0.25, 0.25, 0.5, 0.5, 0.5).finished();
  /// Limit on the norm of the linear velocity, m/s (0: none).
  double max_linear_speed_mps = 0.25;
  /// Limit on the norm of the angular velocity, rad/s (0: none).
  double max_angular_speed_radps = 0.5;
  /// m/s^2 and rad/s^2, > 0.
  Vector6d max_acceleration = (Vector6d() << 0.5, 0.5, 0.5, 1.0, 1.0, 1.0).finished();
  /// Deceleration of a stop (mode OFF: the ramp to zero), m/s^2 and rad/s^2, > 0; a stop never ramps
  /// slower than max_acceleration. Braking may be harder than accelerating: a pause or a lost commander must
  /// bring the robot to rest quickly, and the carried load is felt at the wrist only while the robot brakes.
  Vector6d stop_deceleration = (Vector6d() << 0.5, 0.5, 0.5, 1.0, 1.0, 1.0).finished();
};

/// The first rule `limits` break (pointer relative to the limits object), if any.
std::optional<ConfigProblem> find_problem(const MotionLimits& limits);

/// The tool hanging below the F/T sensor (gripper), for weight compensation.
struct ToolModel {
  double mass_kg = 0.0;                                                   ///< >= 0
  Eigen::Vector3d center_of_mass_m = Eigen::Vector3d::Zero();             ///< in the sensor frame
};

/// Setup-time configuration of RobotAdmittance. Field names follow the configuration file's keys.
struct RobotAdmittanceConfig {
  ControlFrame frame = ControlFrame::kBase;
  AdmittanceGains gains;
  /// Axes that respond to force; the others ignore it (a reference twist still passes on them).
  std::array<bool, 6> selected_axes{true, true, true, true, true, true};
  /// Force deadband N and torque deadband N m per axis, >= 0 (continuous: f - sign(f) * d outside).
  Vector6d deadband = (Vector6d() << 3.0, 3.0, 3.0, 0.5, 0.5, 0.5).finished();
  /// First-order low-pass on the compensated wrench, Hz (0: off). Below the loop's Nyquist rate.
  double force_filter_cutoff_hz = 20.0;
  /// First-order low-pass on the reference twist, Hz (0: off). A reference arrives in steps (a
  /// 30 Hz servo, a joystick); each step would otherwise jerk the carried load, whose inertia the
  /// wrist then feels as a force spike.
  double reference_filter_cutoff_hz = 3.0;
  MotionLimits limits;
  ToolModel tool;
  /// Constant sensor offset subtracted from every sample (sensor frame, about the sensor origin).
  Wrench sensor_bias;
  /// TCP position in the sensor frame, m: the point whose velocity is commanded and about which
  /// torques are taken.
  Eigen::Vector3d tcp_in_sensor_m = Eigen::Vector3d::Zero();
  /// Gravity in the base frame, m/s^2 (a robot mounted upright: (0, 0, -9.81)).
  Eigen::Vector3d gravity_base_mps2{0.0, 0.0, -9.81};
  /// A wrench sample older than this is stale: zero output and fault WRENCH_STALE.
  Seconds wrench_timeout{0.02};
  /// A reference older than this is not applied (treated as no reference; not a fault).
  Seconds reference_timeout{0.2};
  /// A time step outside (0, max_time_step] is refused (fault TIME_STEP_INVALID, zero output).
  Seconds max_time_step{0.05};
  /// Plausibility bounds on the norm of the measured force (N) and torque (N m): above is a sensor or
  /// transport fault (WRENCH_IMPLAUSIBLE), never a command.
  double max_plausible_force_n = 1000.0;
  double max_plausible_torque_nm = 100.0;
  /// Time over which a gain change is blended in (smoothstep), so the output never jumps.
  Seconds gain_transition_time{0.5};
};

/// The first rule `config` breaks (pointer relative to the configuration object), if any.
std::optional<ConfigProblem> find_problem(const RobotAdmittanceConfig& config);

/// One F/T sensor sample as measured: sensor frame, about the sensor origin, tool weight included.
struct WrenchSample {
  Wrench wrench_sensor;
  /// Now minus the sample's measurement stamp.
  Seconds age{0.0};
};

/// A reference twist of the TCP.
struct ReferenceInput {
  ReferenceSource source = ReferenceSource::kNone;  ///< who produced it
  Twist twist;                                      ///< TCP velocity (m/s, rad/s) in `frame`
  ControlFrame frame = ControlFrame::kBase;
  Seconds age{0.0};                                 ///< now minus the reference's stamp
};

/// The law's state as reported with each output.
enum class AdmittanceState { kOff, kStopping, kActive, kFault };
/// Why the output is zero. Invalid input (non-finite, implausible) latches until set_mode() is
/// called again; a stale wrench or a bad time step clears itself with the next good sample.
enum class AdmittanceFault {
  kNone,
  kWrenchStale,         ///< WRENCH_STALE: sample older than wrench_timeout
  kWrenchNotFinite,     ///< WRENCH_NOT_FINITE: NaN or infinity in the sample (latched)
  kWrenchImplausible,   ///< WRENCH_IMPLAUSIBLE: above the plausibility bounds (latched)
  kOrientationInvalid,  ///< ORIENTATION_INVALID: non-finite or non-unit quaternion (latched)
  kReferenceInvalid,    ///< REFERENCE_INVALID: non-finite reference twist (latched)
  kTimeStepInvalid,     ///< TIME_STEP_INVALID: dt not in (0, max_time_step]
};
/// What happened to the reference in this step.
enum class ReferenceStatus { kNotSelected, kApplied, kStale, kOtherSource };

/// "OFF", "STOPPING", "ACTIVE", "FAULT".
std::string_view to_string(AdmittanceState state);
/// The fault code, e.g. "WRENCH_STALE" ("NONE" for kNone).
std::string_view to_string(AdmittanceFault fault);
/// "NOT_SELECTED", "APPLIED", "STALE", "OTHER_SOURCE".
std::string_view to_string(ReferenceStatus status);

struct AdmittanceStatus {
  AdmittanceState state = AdmittanceState::kOff;
  AdmittanceFault fault = AdmittanceFault::kNone;
  bool fault_latched = false;            ///< the fault holds until set_mode() is called
  ReferenceStatus reference = ReferenceStatus::kNotSelected;
  bool velocity_limited = false;         ///< a velocity limit clipped the output this step
  bool acceleration_limited = false;     ///< an acceleration limit clipped the output this step
  bool gains_blending = false;           ///< a gain change is being blended in
};

struct AdmittanceOutput {
  /// Commanded TCP twist in `frame` (m/s, rad/s); zero on a fault.
  Twist twist;
  ControlFrame frame = ControlFrame::kBase;
  AdmittanceStatus status;
  /// The compensated (tool weight and bias removed) wrench about the TCP, base frame, unfiltered:
  /// the contact wrench the load exerts on the robot. Zero when the sample was not usable.
  Wrench wrench_base;
  /// The filtered, deadbanded wrench that drove the law, control frame.
  Wrench wrench_applied;
};

/// The measured wrench minus the sensor bias and the tool's weight: gravity m*g rotated into the
/// sensor frame and its torque c x (m*g) about the sensor origin. `R_base_sensor` is the sensor's
/// orientation in the base frame; the result stays in the sensor frame, about the sensor origin.
Wrench compensate_tool_weight(const Wrench& measured_sensor, const Eigen::Matrix3d& R_base_sensor,
                              const ToolModel& tool, const Eigen::Vector3d& gravity_base_mps2,
                              const Wrench& sensor_bias = Wrench{});

/// The robot admittance law (see the file comment).
class RobotAdmittance {
 public:
  /// @throws rigger::ConfigError (file "RobotAdmittanceConfig", pointer of the field) when `config`
  ///   breaks a rule of find_problem().
  explicit RobotAdmittance(RobotAdmittanceConfig config);

  /// Switches mode. Any switch acknowledges (clears) a latched fault. Leaving OFF restarts the law
  /// from the current output (no jump); entering OFF brings the output to zero at the acceleration
  /// limits (state STOPPING, then OFF).
  void set_mode(AdmittanceMode mode);
  AdmittanceMode mode() const { return mode_; }

  /// Blends new gains in over gain_transition_time. On axes whose current stiffness is zero the
  /// spring is re-anchored at the current position first, so adding stiffness after free guiding
  /// holds the robot where it is instead of pulling it back. Refused (nothing changes) when a gain
  /// breaks a rule of find_problem(). The current target again changes nothing either: a blend under way
  /// goes on, and no spring is re-anchored (admittance_control passes every command's gains).
  RequestResult set_gains(const AdmittanceGains& gains);
  /// The gains in effect at the last step (blending towards target_gains()).
  AdmittanceGains current_gains() const;
  /// The gains being blended to.
  AdmittanceGains target_gains() const;

  /// New limits, effective next step; a lower velocity limit is reached at the acceleration limit.
  RequestResult set_limits(const MotionLimits& limits);
  /// Selects the axes that respond to force; a deselected axis's deviation decays under the
  /// acceleration limits.
  void set_selected_axes(const std::array<bool, 6>& selected);

  /// Chooses which reference source is followed; references from other sources are ignored.
  void set_reference_source(ReferenceSource source);
  ReferenceSource reference_source() const { return reference_source_; }

  /// Re-anchors the virtual springs at the current position (the deviation x becomes zero).
  void reset_anchor();

  /// One control cycle of length `dt` (the time since the previous call).
  /// @param wrench                  the latest F/T sample and its age
  /// @param orientation_base_sensor the sensor's (and TCP's) orientation in the base frame
  /// @param reference               the latest reference twist (ignored unless its source is selected)
  /// @return the TCP twist command and the status; never throws.
  AdmittanceOutput step(Seconds dt, const WrenchSample& wrench, const Eigen::Quaterniond& orientation_base_sensor,
                        const ReferenceInput& reference);

  const RobotAdmittanceConfig& config() const { return config_; }

 private:
  using GainMatrix = Eigen::Matrix<double, 6, 3>;  // columns: mass, damping, stiffness

  AdmittanceOutput fault_output(AdmittanceFault fault, bool latch);
  AdmittanceOutput stopping_output(double dt_s);
  void reset_state();

  RobotAdmittanceConfig config_;
  AdmittanceMode mode_ = AdmittanceMode::kOff;
  ReferenceSource reference_source_ = ReferenceSource::kNone;
  AdmittanceFault latched_fault_ = AdmittanceFault::kNone;
  GainBlend<GainMatrix> gains_;
  std::array<CachedAxisDiscretisation, 6> discretisation_;
  Vector6d deviation_ = Vector6d::Zero();           // x: position deviation from the reference path
  Vector6d deviation_rate_ = Vector6d::Zero();      // e = v - v_ref
  Vector6d filtered_wrench_ = Vector6d::Zero();     // low-pass state, control frame
  Vector6d filtered_reference_ = Vector6d::Zero();  // low-pass state, control frame
  Vector6d last_output_ = Vector6d::Zero();         // last commanded twist, control frame
};

}  // namespace rigger::control
