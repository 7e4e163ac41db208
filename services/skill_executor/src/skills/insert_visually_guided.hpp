#pragma once
/// @file
/// InsertVisuallyGuided: brings the crane-carried load, held by the robot, to its insertion pose on the
/// target by position-based visual servoing; robot and crane follow under admittance control.
///
///   check_crane ─▶ lookup ─▶ crane_external ─▶ track ─▶ engage ─▶ servo ──converged for settle_s──▶ hold ─▶ SUCCESS
///
/// check_crane: a fresh rigger/crane/state shows a healthy crane (precondition of holding its load).
/// lookup: the object's CAD feature `insertion` (world model FEATURES query): its target must be
/// `target`; goal = insertion.pose_in_target with the stand-off (standoff_{x,y,z}_m, target frame) added.
/// crane_external: CRANE_REQUEST_EXTERNAL until granted.
/// track: TRACK_CONTINUOUS for object and target; waits for a good pose (tracked, quality ≥ min_quality)
/// of both.
/// engage: rigger/admittance/command ROBOT_AND_CRANE, reference VISUAL_SERVO, servo_object = object,
/// servo_target = target, servo_goal_in_target = goal, source = executor id; confirmed by the state.
/// servo: succeeds when the admittance state reports servo_converged with servo_error_m ≤ tolerance_m
/// and servo_error_rad ≤ tolerance_rad continuously for settle_s. Fails with CRANE_FAULT (crane state:
/// fault, link down, e-stop, silence; or admittance fault CRANE_FAULT for kAdmittanceFaultGrace),
/// ADMITTANCE_FAULT (any other admittance fault lasting kAdmittanceFaultGrace), ADMITTANCE_PREEMPTED (another
/// mode/reference commanded), TRACKING_LOST (no good tracker pose of object or target for tracking_lost_s, or the servo
/// reports a tracking stop for that long), TIMEOUT (not settled within timeout_s, counted from engage). hold:
/// admittance OFF (confirmed with robot and crane at rest) and TRACK_STOP of object and target. OFF, not ROBOT: with admittance OFF the
/// robot holds its pose stiffly (no twist setpoints) and the crane its position, so the operator's screwing forces in
/// the following Screw step cannot push the load out of the target, whereas ROBOT mode (no reference) would yield to
/// them. The magnet stays on throughout.
///
/// Safe stops: check_crane, lookup, crane_external → nothing commanded; track → TRACK_STOP (object and
/// target); engage, servo, hold → admittance OFF (robot and crane ramp to zero), TRACK_STOP, and wait for the
/// admittance state to report OFF at rest. The magnet is never touched.
/// Claims robot, crane, camera, $object, $target. Pre: attached(robot,$object), localized($object),
/// localized($target). Post: inserted($object,$target).

#include <optional>
#include <string>

#include <Eigen/Geometry>

#include "rigger/skill_sdk/cell_devices.hpp"
#include "rigger/skill_sdk/skill.hpp"
#include "sdk.hpp"

namespace rigger::skill_executor {

/// The servo goal from an object's features JSON: insertion.pose_in_target (its target must be
/// `target`) translated by `standoff_in_target_m`. Returns an error text or the goal.
std::optional<std::string> insertion_goal(const nlohmann::json& features, const std::string& target,
                                          const Eigen::Vector3d& standoff_in_target_m, Eigen::Isometry3d& goal);

class InsertVisuallyGuidedSkill final : public CraneSkill {
 public:
  static const skill::SkillDescription& describe();
  InsertVisuallyGuidedSkill();

  static constexpr std::chrono::seconds kWorldTimeout{2};
  /// How long `track` waits for the first good poses of both objects.
  static constexpr std::chrono::seconds kTrackStartTimeout{3};

 private:
  void check_crane();
  void lookup();
  void crane_external();
  void start_tracking();
  void engage();
  void servo();
  void on_admittance(const AdmittanceSnapshot& s);
  void on_pose(int index, const TrackedObjectSample& s);
  void hold();
  void safe_stop(const SafeStopDone& done);
  void stop_tracking(const SafeStopDone& done);
  bool good(const TrackedObjectSample& s) const;
  /// (Re)starts the one-shot timer in `slot` (cancelling the previous one).
  void rearm(std::uint64_t& slot, std::chrono::nanoseconds delay, std::function<void()> handler);
  void cancel_timers();

  std::string object_, target_;
  double min_quality_ = 0.5;
  Eigen::Isometry3d goal_ = Eigen::Isometry3d::Identity();
  bool seen_[2] = {false, false};  // track: a good pose of object / target arrived
  std::uint64_t lost_timer_[2] = {0, 0};
  std::uint64_t servo_stop_timer_ = 0;
  std::uint64_t settle_timer_ = 0;
  std::optional<WallTime> last_progress_;
  double last_error_m_ = -1.0, last_error_rad_ = -1.0;
};

}  // namespace rigger::skill_executor
