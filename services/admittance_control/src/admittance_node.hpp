#pragma once
/// @file
/// The admittance_control DDS node: wrench, robot state, commands and references in; the robot's
/// twist setpoints (robot loop), the crane's velocity setpoints (crane loop) and the service state
/// out. The laws are RobotAdmittance and CraneAdmittance (docs/control.md); this is plumbing.

#include <cstdint>
#include <optional>
#include <string>

#include "control_config.hpp"
#include "crane_admittance.hpp"
#include "rigger/base/time.hpp"
#include "rigger/dds/pubsub.hpp"
#include "rigger/dds/service.hpp"
#include "robot_admittance.hpp"

namespace rigger::control {

inline constexpr const char* kWrenchTopic = "rigger/robot/wrench";
inline constexpr const char* kRobotStateTopic = "rigger/robot/state";
inline constexpr const char* kCommandTopic = "rigger/admittance/command";
inline constexpr const char* kJoystickTopic = "rigger/operator/joystick";
inline constexpr const char* kTrackerPoseTopic = "rigger/tracker/pose";
inline constexpr const char* kCmdTwistTopic = "rigger/robot/cmd_twist";
inline constexpr const char* kCraneCmdTopic = "rigger/crane/cmd_velocity";
inline constexpr const char* kStateTopic = "rigger/admittance/state";

/// Fault code of the node itself (the laws' codes are theirs, e.g. WRENCH_STALE, FORCE_STALE):
/// no robot state received yet, so the sensor's orientation is unknown and the output is zero.
inline constexpr const char* kFaultNoRobotState = "ROBOT_STATE_MISSING";

/// Configuration: the keys of load_control_config() ("robot", "crane", "visual_servo"; rates are
/// robot.rate_hz and crane.rate_hz) and these (optional):
///   "twist_timeout_s": number in [0.002, 1], default 0.05 — timeout_s of each cmd_twist
///   "crane_timeout_s": number in [0.02, 2], default 0.2 — timeout_s of each crane cmd_velocity
/// The robot base's orientation is taken to be the world's (true in the simulated cell).
/// @throws ConfigError (exit 2).
class AdmittanceNode : public dds::Node {
 public:
  explicit AdmittanceNode(dds::ServiceContext& ctx);
  /// Leaves the robot and the crane with a zero setpoint.
  ~AdmittanceNode() override;

  /// Setpoints published so far (loop thread).
  std::uint64_t twist_seq() const { return twist_seq_; }
  std::uint64_t crane_seq() const { return crane_seq_; }

 private:
  void on_wrench();
  void on_robot_state();
  void on_command();
  void on_joystick();
  void on_tracker_pose();
  void robot_step();
  void crane_step();
  void publish_twist(const Vector6d& twist_base);
  void publish_crane(const Eigen::Vector3d& velocity_world_mps);
  void publish_state();
  std::string fault_code() const;

  dds::ServiceContext& ctx_;
  double twist_timeout_s_;
  double crane_timeout_s_;
  ControlConfig config_;
  RobotAdmittance robot_;
  CraneAdmittance crane_;
  AdmittanceMode mode_ = AdmittanceMode::kOff;
  ReferenceSource reference_ = ReferenceSource::kNone;
  std::uint64_t last_command_seq_ = 0;

  // Latest inputs.
  std::optional<WallTime> wrench_stamp_;
  Wrench wrench_sensor_;
  std::optional<Eigen::Quaterniond> orientation_base_sensor_;
  std::optional<WallTime> joystick_stamp_;
  Twist joystick_twist_;

  // Latest outputs.
  AdmittanceOutput robot_output_;
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
  dds::Writer<rigger_sensing_TwistCommand> cmd_twist_;
  dds::Writer<rigger_crane_CraneVelocityCommand> crane_cmd_;
  dds::Writer<rigger_admittance_AdmittanceState> state_;
};

}  // namespace rigger::control
