#pragma once
// The crane's drives and rope as laws, apart from MuJoCo: a travel drive in velocity mode, the
// hoist drum, and the rope's tension.  Pure C++.

namespace rigger::sim {

/// A travel drive (bridge or trolley) as a frequency converter in velocity mode runs it: the
/// setpoint goes through the drive's own ramp (its acceleration limit, above the PLC's ramps, so
/// it only shows when the PLC stops abruptly, e.g. on e-stop), the ramped velocity is integrated
/// into a position reference, and position and velocity loops track it, so the axis holds still
/// under a push when the setpoint is zero.  The result is the acceleration to apply; the caller
/// turns it into a force, and the motor's force limit caps it.  Not thread-safe.
class TravelDrive {
 public:
  struct Params {
    double position_min_m = 0.0;  ///< mechanical end stops: the reference stays inside
    double position_max_m = 1.0;
    double velocity_time_constant_s = 0.02;
    double position_gain_per_s = 10.0;
    double max_following_error_m = 0.05;  ///< the reference never runs ahead further than this
    double max_accel_mps2 = 3.0;          ///< the drive's ramp (what its motor can brake)
  };

  explicit TravelDrive(const Params& params);

  /// Restart at a measured position, at rest.
  void reset(double position_m);

  /// The velocity the drive should run at (m/s); not checked here (the PLC limits it).
  void set_velocity_setpoint(double velocity_mps) { setpoint_mps_ = velocity_mps; }

  /// Desired acceleration (m/s^2) for this step, given the measured state.
  double update(double position_m, double velocity_mps, double dt_s);

  [[nodiscard]] double reference_position_m() const { return reference_m_; }
  [[nodiscard]] double velocity_setpoint_mps() const { return setpoint_mps_; }
  /// The setpoint after the drive's ramp (m/s).
  [[nodiscard]] double ramped_velocity_mps() const { return ramped_mps_; }

 private:
  Params params_;
  double reference_m_ = 0.0;
  double setpoint_mps_ = 0.0;
  double ramped_mps_ = 0.0;
};

/// The hoist drum: the rope paid out follows the velocity setpoint through a first-order drive
/// with an acceleration limit, and stops at the ends of its range.  Its reaction to the load is
/// neglected (a geared drum is stiff).  Not thread-safe.
class HoistDrum {
 public:
  struct Params {
    double payout_min_m = 0.5;
    double payout_max_m = 3.8;
    double velocity_time_constant_s = 0.05;
    double max_accel_mps2 = 2.0;  ///< what the drive and brake can do, above the PLC's ramps
  };

  explicit HoistDrum(const Params& params);

  void reset(double payout_m);
  void set_velocity_setpoint(double velocity_mps) { setpoint_mps_ = velocity_mps; }
  void update(double dt_s);

  [[nodiscard]] double payout_m() const { return payout_m_; }
  [[nodiscard]] double payout_rate_mps() const { return rate_mps_; }
  [[nodiscard]] double velocity_setpoint_mps() const { return setpoint_mps_; }

 private:
  Params params_;
  double payout_m_ = 0.0;
  double rate_mps_ = 0.0;
  double setpoint_mps_ = 0.0;
};

/// The rope between drum and hook as a stiff spring-damper that pulls but never pushes.
struct RopeParams {
  double stiffness_n_per_m = 2.0e5;  ///< about 2 mm stretch under a 40 kg load
  double damping_n_s_per_m = 2000.0;
};

/// Rope tension (N, >= 0) for a hook at `hook_distance_m` below the sheave moving at
/// `hook_speed_mps` (positive away from the sheave), with `payout_m` of rope paid out at
/// `payout_rate_mps`.  Zero when the rope is slack (hook closer than the payout).
double rope_tension_n(double hook_distance_m, double hook_speed_mps, double payout_m,
                      double payout_rate_mps, const RopeParams& params);

}  // namespace rigger::sim
