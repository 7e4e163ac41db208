#pragma once
/// @file
/// The admittance_control DDS node: wrench, robot state, commands and references in; the robot's
/// twist setpoints (robot loop), the crane's velocity setpoints (crane loop) and the service state
/// out. The laws are RobotAdmittance, CraneAdmittance and VisualServo (docs/control.md); this is
/// plumbing, plus the node's own safety: commander liveliness and the crane's faults.
/// Everything runs on the service's event loop thread (not thread-safe otherwise).

#include <cstdint>
#include <map>
#include <memory>
#include <optional>
#include <string>

#include "control_config.hpp"
#include "crane_admittance.hpp"
#include "rigger/base/time.hpp"
#include "rigger/cell_follower/cell_follower.hpp"
#include "rigger/dds/pubsub.hpp"
#include "rigger/safety/safe_stop.hpp"
#include "rigger/service/service.hpp"
#include "rigger/service/service_state.hpp"
#include "robot_admittance.hpp"
#include "visual_servo.hpp"

namespace rigger::control {

/// Fault codes of the node itself (the laws' codes are theirs, e.g. WRENCH_STALE, FORCE_STALE).
/// No robot state received yet, so the sensor's orientation is unknown and the output is zero.
inline constexpr const char* kFaultNoRobotState = "ROBOT_STATE_MISSING";
/// The commanding process (AdmittanceCommand.source) was lost: mode OFF, latched until the next command.
inline constexpr const char* kFaultCommanderLost = "COMMANDER_LOST";
/// A safe stop of the robot, the crane or the admittance controller is in force (rigger/safety/stop).
inline constexpr const char* kFaultSafeStop = "SAFE_STOP";
/// rigger/crane/state reported a fault or link down, or went silent, in ROBOT_AND_CRANE: mode OFF
/// (robot and crane ramp to zero), latched until the next command.
inline constexpr const char* kFaultCraneFault = "CRANE_FAULT";
/// A VISUAL_SERVO command without object or target, or with a goal that is not a finite rigid pose:
/// refused, mode OFF, latched until the next command.
inline constexpr const char* kFaultServoRequestInvalid = "SERVO_REQUEST_INVALID";
/// While the servo's reference is stopped, fault_code is VisualServo's stop reason (LOAD_QUALITY_LOW,
/// TARGET_QUALITY_LOW, LOAD_POSE_STALE, TARGET_POSE_STALE, LOAD_POSE_INVALID, TARGET_POSE_INVALID):
/// not latched, the mode stays, the robot stays compliant with a zero reference.

/// Configuration: load_control_config()'s keys (control_settings(), docs/config-reference.md): the
/// node's (timeouts, cell file, robot id, rope offset) and the laws' ("robot", "crane", "visual_servo").
/// With crane.rope_offset_gain_per_s > 0 the measured rope offset is rope_object's rope_attachment point
/// (tracker pose) minus the hook (rigger/crane/state position), horizontal part; it needs cell_file.
/// Without a tracker pose of it at most rope_offset_max_age_s old (tracking lost, or the tracker not
/// running continuously) the law gets no offset and runs on the force.
/// Frames: the wrench, the robot state and cmd_twist are in the robot base frame B; tracker poses
/// and the crane (bridge x, trolley y, hoist z) in the world frame; the crane frame is taken to be
/// the world frame (true in the simulated cell). The published AdmittanceState is in B.
/// With cell_file, the node follows the cell's revisions (rigger/world/cell): a revision that moves the
/// robot base or the rope attachment is taken while the mode is OFF, and refused while a law runs (a base
/// that jumped under a running law would jump its commands); apply it again when admittance is off.
/// @throws ConfigError (exit 2).
class AdmittanceNode : public service::Node {
 public:
  explicit AdmittanceNode(service::ServiceContext& ctx);
  /// Leaves the robot and the crane with a zero setpoint.
  ~AdmittanceNode() override;

  /// Setpoints published so far (loop thread).
  std::uint64_t twist_seq() const { return twist_seq_; }
  std::uint64_t crane_seq() const { return crane_seq_; }
  /// The robot base's pose in the world (from the cell file, else identity).
  const Eigen::Isometry3d& pose_world_base() const { return pose_world_base_; }
  /// The cell revision follower; null without cell_file (loop thread).
  const cell_follower::CellFollower* cell_follower() const { return follower_.get(); }

 private:
  /// The latest tracker sample of one object.
  struct TrackerSample {
    Eigen::Isometry3d pose_world = Eigen::Isometry3d::Identity();
    double quality = 0.0;
    bool tracked = false;
    WallTime stamp{};
  };
  /// The latest crane state (rigger/crane/state).
  struct CraneSample {
    bool fault = false;
    bool link_ok = false;
    std::string fault_text;
    dds::EventLoop::Clock::time_point received{};
    Eigen::Vector3d position_m = Eigen::Vector3d::Zero();  ///< bridge, trolley, hook height (= world)
  };

  void on_wrench();
  void on_robot_state();
  void on_command();
  void on_joystick();
  void on_tracker_pose();
  void on_crane_state();
  void on_directory();
  cell_follower::Outcome on_revision(const cell_follower::FollowedRevision& revision);
  void robot_step();
  void crane_step();
  void servo_step();
  void check_commander();
  void check_crane();
  /// The measured rope offset for the crane law, when pose_rope_attachment_ is set and both the tracked
  /// object and the crane state are fresh.
  std::optional<Eigen::Vector3d> rope_offset_world() const;
  /// Mode OFF (both laws ramp to zero) with a node fault latched until the next command.
  void go_off(const std::string& code, const std::string& text);
  /// Why a VISUAL_SERVO command is refused ("" when it is fine); sets servo_ on success.
  std::string accept_servo_request(const rigger_admittance_AdmittanceCommand& c);
  void publish_twist(const Vector6d& twist_base);
  void publish_crane(const Eigen::Vector3d& velocity_world_mps);
  void publish_state();
  std::string fault_code() const;
  /// True while the servo runs but its reference is stopped (quality, age, invalid pose).
  bool servo_stopped() const;

  service::ServiceContext& ctx_;
  ControlConfig config_;
  double twist_timeout_s_;
  double crane_timeout_s_;
  Eigen::Isometry3d pose_world_base_;
  std::string robot_id_;
  Seconds crane_state_timeout_;
  Seconds commander_grace_;
  std::string rope_object_;
  Seconds rope_offset_max_age_;
  // Where the rope hooks into rope_object_, in its frame; set when crane.rope_offset_gain_per_s > 0.
  std::optional<Eigen::Isometry3d> pose_rope_attachment_;
  RobotAdmittance robot_;
  CraneAdmittance crane_;
  AdmittanceMode mode_ = AdmittanceMode::kOff;
  ReferenceSource reference_ = ReferenceSource::kNone;
  std::uint64_t last_command_seq_ = 0;
  dds::EventLoop::Clock::time_point mode_since_{};

  // Node faults (latched until the next accepted command).
  std::string node_fault_;
  std::string node_fault_text_;

  // Commander liveliness.
  std::string commander_;
  bool commander_seen_ = false;
  dds::EventLoop::Clock::time_point commander_since_{};

  // Visual servo: the request and the latest result.
  std::optional<VisualServo> servo_;
  std::string servo_object_;
  std::string servo_target_;
  std::optional<ServoOutput> servo_output_;
  std::optional<WallTime> servo_reference_stamp_;
  Twist servo_reference_base_;  // at the TCP, base frame
  std::map<std::string, TrackerSample> tracked_;

  // Latest inputs.
  std::optional<WallTime> wrench_stamp_;
  Wrench wrench_sensor_;
  std::optional<Eigen::Quaterniond> orientation_base_sensor_;
  std::optional<Eigen::Vector3d> tcp_position_base_;
  std::optional<WallTime> joystick_stamp_;
  Twist joystick_twist_;
  std::optional<CraneSample> crane_state_;

  // Latest outputs.
  AdmittanceOutput robot_output_;
  Twist robot_twist_base_;  // the last commanded TCP twist, base frame
  CraneOutput crane_output_;
  bool robot_published_ = false;  // a non-zero stream is out: the next OFF step sends one zero
  bool crane_published_ = false;
  std::string last_fault_code_;
  std::uint64_t twist_seq_ = 0;
  std::uint64_t crane_seq_ = 0;
  std::optional<dds::EventLoop::Clock::time_point> last_robot_step_;
  std::optional<dds::EventLoop::Clock::time_point> last_crane_step_;

  dds::Reader<rigger_sensing_WrenchStamped> wrenches_;
  dds::Reader<rigger_robot_RobotState> robot_states_;
  dds::Reader<rigger_admittance_AdmittanceCommand> commands_;
  dds::Reader<rigger_sensing_TwistCommand> joystick_;
  dds::Reader<rigger_vision_TrackedPose> tracker_poses_;
  dds::Reader<rigger_crane_CraneState> crane_states_;
  service::ServiceDirectory directory_;
  dds::Writer<rigger_sensing_TwistCommand> cmd_twist_;
  dds::Writer<rigger_crane_CraneVelocityCommand> crane_cmd_;
  dds::Writer<rigger_admittance_AdmittanceState> state_;
  safety::SafeStopListener safe_stop_;
  std::unique_ptr<cell_follower::CellFollower> follower_;  // last: its callback uses the members above
};

}  // namespace rigger::control
