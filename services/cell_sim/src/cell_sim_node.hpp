#pragma once
/// @file
/// The cell_sim process's DDS plumbing: the robot driver's, gripper's, camera's and the simulator's
/// own topics (docs/cell-sim.md), wired to the physics thread (SimRunner) and the camera thread
/// (CameraWorker). Commands are checked on the event loop's thread and go to the physics thread
/// through its mailbox; reports are published from the physics and camera threads (Cyclone writers
/// are thread-safe).

#include <atomic>
#include <chrono>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>

#include <CLI/CLI.hpp>

#include "camera_worker.hpp"
#include "cell_revisions.hpp"
#include "command_gate.hpp"
#include "rigger/cell_follower/cell_follower.hpp"
#include "rigger/dds/pubsub.hpp"
#include "rigger/ros2/types.hpp"
#include "rigger/safety/safe_stop.hpp"
#include "rigger/service/service.hpp"
#include "sim_runner.hpp"

namespace rigger::cell_sim {

/// Frame ids on the wire: the robot's base is the cell entity "robot"; the wrist sensor reports in
/// the tool frame (magnet face centre, flange axes); ground truth is in the world frame.
inline constexpr const char* kBaseFrame = "robot";
inline constexpr const char* kToolFrame = "tool";
inline constexpr const char* kWorldFrame = "world";

/// Command-line overrides of the configuration (for tests and the benchmark).
struct CommandLine {
  std::optional<std::uint16_t> plc_port;
  std::optional<double> real_time_factor;
  /// The cell file instead of the configuration's `cell_file` ("": the configuration's). The console
  /// starts its rehearsal cell on a revision's document this way (docs/console.md).
  std::string cell_file;
  void add_to(CLI::App& app);
};

/// Configuration: deploy/config/cell_sim.json, keys in docs/cell-sim.md.
class CellSimNode : public service::Node, private SimOutputs {
 public:
  /// @throws ConfigError (bad configuration, cell file or model), crane::ModbusError (port in use), DdsError.
  CellSimNode(service::ServiceContext& ctx, const CommandLine& command_line);
  /// Stops the physics thread with the arm and the crane stopped and the Modbus server closed.
  ~CellSimNode() override;

 private:
  // SimOutputs (physics and camera threads)
  void publish_wrench(const sim::Wrench& wrench_tool, WallTime stamp) override;
  void publish_robot_state(const RobotReport& report, WallTime stamp) override;
  void publish_gripper_state(const GripperReport& report, WallTime stamp) override;
  void publish_motion_status(const MotionReport& report, WallTime stamp) override;
  void publish_ground_truth(const GroundTruth& truth, WallTime stamp) override;
  void publish_status(const StatusReport& status, WallTime stamp) override;
  void publish_control_result(const ControlResult& result, WallTime stamp) override;
  /// The camera scene as configured (camera/width, height) and as the camera really is (pose_world_camera_true_).
  /// @throws std::invalid_argument for a size of another aspect ratio.
  sim::CameraScene as_rendered(sim::CameraScene scene) const;
  /// What the camera thread renders: the image while a reader of it is matched, depth likewise.
  CameraDemand camera_demand() const;
  /// The grey image and (when the renderer makes one) the depth image of one frame, same stamp (camera thread).
  void publish_images(const CameraImages& images, WallTime stamp);
  /// `image` on the wire (not copied: valid while `image` is), with the camera's frame id.
  rigger_vision_Image wire_image(const cv::Mat& image, const char* encoding, WallTime stamp) const;
  void publish_camera_info(const sim::CameraModel& camera);
  void publish_joint_states(const sim::RobotState& state, WallTime stamp);

  // event loop thread
  void on_twist();
  void on_ros2_twist();
  /// A twist command from either side (rigger's topic, or a ROS 2 TwistStamped made into one).
  void take_twist(const rigger_sensing_TwistCommand& c);
  void on_motion();
  void on_gripper();
  void on_sim_control();
  /// A cell revision (rigger/world/cell): its moved free objects put at their new poses, or refused.
  cell_follower::Outcome on_revision(const cell_follower::FollowedRevision& next);
  /// A revision that needs the model built anew: the physics (and the camera's renderer) built from it here,
  /// swapped in by the physics thread, or refused.
  cell_follower::Outcome rebuild(const cell_follower::FollowedRevision& next, const RevisionPlan& plan);
  /// The revision becomes the running cell.
  cell_follower::Outcome take(const cell_follower::FollowedRevision& next);
  void refuse_motion(const std::string& motion_id, const std::string& code, const std::string& message);
  bool log_allowed(std::chrono::steady_clock::time_point& last);

  service::ServiceContext& ctx_;
  CellSimConfig config_;
  Eigen::Isometry3d pose_world_base_ = Eigen::Isometry3d::Identity();
  /// Where the camera really is, for the process' life: the cell file's drawing at start times
  /// camera/pose_error. Revisions that draw the camera elsewhere do not move it.
  Eigen::Isometry3d pose_world_camera_true_ = Eigen::Isometry3d::Identity();
  CommandGate twist_gate_;
  std::uint64_t twists_refused_ = 0;
  std::chrono::steady_clock::time_point last_twist_log_{};
  std::chrono::steady_clock::time_point last_motion_log_{};

  // rigger's robot and camera topics, or (config ros2_driver) a ROS 2 driver's: one of each pair is open.
  std::optional<dds::Writer<rigger_sensing_WrenchStamped>> wrench_;
  std::optional<dds::Writer<geometry_msgs_msg_dds__WrenchStamped_>> ros2_wrench_;
  std::optional<dds::Writer<rigger_vision_Image>> image_;
  std::optional<dds::Writer<sensor_msgs_msg_dds__Image_>> ros2_image_;
  /// rigger/camera/depth: with the mujoco renderer on rigger's topics.
  std::optional<dds::Writer<rigger_vision_Image>> depth_;
  std::optional<dds::Writer<rigger_robot_RobotState>> robot_state_;
  std::optional<dds::Writer<sensor_msgs_msg_dds__JointState_>> ros2_joint_states_;
  std::optional<dds::Reader<rigger_sensing_TwistCommand>> twist_;
  std::optional<dds::Reader<geometry_msgs_msg_dds__TwistStamped_>> ros2_twist_;
  std::uint64_t ros2_twist_seq_ = 0;
  dds::Writer<rigger_robot_MotionStatus> motion_status_;
  dds::Writer<rigger_robot_GripperState> gripper_state_;
  std::optional<dds::Writer<rigger_vision_CameraInfo>> camera_info_;  // on rigger's topics
  std::optional<dds::Writer<sensor_msgs_msg_dds__CameraInfo_>> ros2_camera_info_;  // as a ROS 2 driver
  rigger_vision_CameraInfo camera_info_wire_{};  // the camera's intrinsics; d borrows camera_info_d_
  std::vector<double> camera_info_d_;
  dds::Writer<rigger_vision_TrackedPose> ground_truth_;
  dds::Writer<rigger_sim_SimEvent> sim_event_;
  dds::Writer<rigger_sim_SimStatus> sim_status_;
  dds::Reader<rigger_robot_MotionCommand> motion_;
  dds::Reader<rigger_robot_GripperCommand> gripper_;
  dds::Reader<rigger_sim_SimControl> sim_control_;
  /// The robot driver's side of the safe stop: "robot" stops the arm and refuses motion, "gripper"
  /// refuses gripper commands (the magnet keeps its state: a load is never dropped).
  std::unique_ptr<safety::SafeStopListener> safe_stop_;

  // Destroyed before the writers they publish through: first the runner (physics thread), then the camera.
  std::unique_ptr<CameraWorker> camera_;
  /// The renderer chosen at start (`auto` resolved then): kept for the process' life, whatever the cell becomes.
  CameraRendererKind camera_kind_ = CameraRendererKind::kRaster;
  std::unique_ptr<SimRunner> runner_;
  /// The cell the physics runs on (its file, then each revision taken) and its document: a revision is
  /// diffed against it, whatever revision it says it changes.
  cell::CellFile running_cell_;
  nlohmann::json running_doc_;
  /// Follows the cell's revisions on the event loop; destroyed first (its callback uses the runner).
  std::unique_ptr<cell_follower::CellFollower> follower_;
};

}  // namespace rigger::cell_sim
