// The cell_sim node's reports: what the physics and camera threads hand it (SimOutputs), on the wire.
// Called on those threads: Cyclone writers are thread-safe, and nothing here touches the event loop.
#include "cell_sim_node.hpp"

#include <cmath>
#include <vector>

#include "camera_renderers.hpp"
#include "rigger/dds/conversions.hpp"
#include "rigger/dds/sequences.hpp"
#include "rigger/protocol/robot.hpp"
#include "rigger/protocol/sim.hpp"
#include "rigger/protocol/vision.hpp"
#include "rigger/ros2/conversions.hpp"
#include "rigger/ros2/qos.hpp"
#include "rigger/sim/camera_scene.hpp"
#include "rigger/sim/cell_geometry.hpp"

namespace rigger::cell_sim {
namespace {

dds::Vector6d six(const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  dds::Vector6d v;
  v << a, b;
  return v;
}

rigger_robot_MotionState to_wire(MotionPhase phase) {
  switch (phase) {
    case MotionPhase::kAccepted:
      return rigger_robot_MOTION_ACCEPTED;
    case MotionPhase::kExecuting:
      return rigger_robot_MOTION_EXECUTING;
    case MotionPhase::kSucceeded:
      return rigger_robot_MOTION_SUCCEEDED;
    case MotionPhase::kFailed:
      return rigger_robot_MOTION_FAILED;
    case MotionPhase::kAborted:
      return rigger_robot_MOTION_ABORTED;
  }
  return rigger_robot_MOTION_FAILED;
}

rigger_robot_RobotMode to_wire_mode(const RobotReport& report) {
  if (report.estop) return rigger_robot_ROBOT_FAULT;
  switch (report.state.mode) {
    case sim::RobotMode::Twist:
      return rigger_robot_ROBOT_VELOCITY;
    case sim::RobotMode::JointMotion:
    case sim::RobotMode::CartesianMotion:
      return rigger_robot_ROBOT_MOTION;
    case sim::RobotMode::Hold:
    case sim::RobotMode::Stopping:
      break;
  }
  return rigger_robot_ROBOT_IDLE;
}

rigger_sim_SimControlKind to_wire(ControlKind kind) {
  switch (kind) {
    case ControlKind::kEstop:
      return rigger_sim_SIM_ESTOP;
    case ControlKind::kSetHoldingForce:
      return rigger_sim_SIM_SET_HOLDING_FORCE;
    case ControlKind::kSetLoadForce:
      return rigger_sim_SIM_SET_LOAD_FORCE;
    case ControlKind::kPlcLink:
      return rigger_sim_SIM_PLC_LINK;
    case ControlKind::kReset:
      break;
  }
  return rigger_sim_SIM_RESET;
}

template <std::size_t N>
void copy3(const Eigen::Vector3d& v, double (&out)[N]) {
  static_assert(N == 3, "three axes");
  for (int i = 0; i < 3; ++i) out[i] = v[i];
}

}  // namespace

// ---- reports --------------------------------------------------------------------------------

void CellSimNode::publish_wrench(const sim::Wrench& wrench_tool, WallTime stamp) {
  rigger_sensing_WrenchStamped w{};
  w.header.stamp = dds::to_wire(stamp);
  w.header.frame_id = const_cast<char*>(kToolFrame);
  w.wrench = dds::to_wire_wrench(six(wrench_tool.force_n, wrench_tool.torque_nm));
  if (ros2_wrench_)
    ros2_wrench_->write(ros2::to_ros2(w));
  else
    wrench_->write(w);
}

void CellSimNode::publish_robot_state(const RobotReport& report, WallTime stamp) {
  const sim::RobotState& s = report.state;
  if (ros2_joint_states_) {
    publish_joint_states(s, stamp);
    return;
  }
  std::vector<double> position(s.position_rad.data(), s.position_rad.data() + sim::kArmJointCount);
  std::vector<double> velocity(s.velocity_rad_per_s.data(), s.velocity_rad_per_s.data() + sim::kArmJointCount);
  rigger_robot_RobotState w{};
  w.header.stamp = dds::to_wire(stamp);
  w.header.frame_id = const_cast<char*>(kBaseFrame);
  w.mode = to_wire_mode(report);
  dds::wire_sequence(w.joint_position, position);
  dds::wire_sequence(w.joint_velocity, velocity);
  w.flange_pose = dds::to_wire(s.pose_base_flange);
  w.tool_pose = dds::to_wire(s.pose_base_tool);
  w.tool_twist = dds::to_wire_twist(six(s.twist_base_tool.linear_mps, s.twist_base_tool.angular_rad_per_s));
  constexpr double kMovingRadPerS = 1e-3;
  w.moving = s.velocity_rad_per_s.cwiseAbs().maxCoeff() > kMovingRadPerS;
  w.fault = dds::wire_string(report.fault);
  w.last_command_seq = report.last_command_seq;
  robot_state_->write(w);
}

// What a ros2_control robot's joint_state_broadcaster publishes: names, positions, velocities and efforts,
// stamped, nothing else. Its order is its own, not the chain's (Humble's comes from a hash map): this driver
// writes the joints last to first, so that the bridge's mapping by name is used on every message.
void CellSimNode::publish_joint_states(const sim::RobotState& s, WallTime stamp) {
  const CellSimConfig::Ros2Driver& r = *config_.ros2_driver;
  constexpr int n = sim::kArmJointCount;
  std::vector<char*> names(n);
  std::vector<double> position(n), velocity(n), effort(n);
  for (int k = 0; k < n; ++k) {
    const int i = n - 1 - k;
    names[k] = dds::wire_string(r.joint_names[static_cast<std::size_t>(i)]);
    position[k] = s.position_rad[i];
    velocity[k] = s.velocity_rad_per_s[i];
    effort[k] = s.torque_nm[i];
  }
  rigger_geometry_Header header{dds::to_wire(stamp), dds::wire_string("")};
  ros2_joint_states_->write(ros2::to_ros2_joint_state(header, names, position, velocity, effort));
}

void CellSimNode::publish_gripper_state(const GripperReport& report, WallTime stamp) {
  rigger_robot_GripperState w{};
  w.header.stamp = dds::to_wire(stamp);
  w.header.frame_id = const_cast<char*>(kToolFrame);
  w.energized = report.state.energized;
  w.contact = report.state.in_contact;
  w.holding = report.state.holding;
  w.holding_force_n = report.state.holding_force_n;
  w.last_command_seq = report.last_command_seq;
  gripper_state_.write(w);
}

void CellSimNode::publish_motion_status(const MotionReport& report, WallTime stamp) {
  rigger_robot_MotionStatus w{};
  w.header.stamp = dds::to_wire(stamp);
  w.header.frame_id = const_cast<char*>(kBaseFrame);
  w.motion_id = dds::wire_string(report.motion_id);
  w.state = to_wire(report.phase);
  w.code = dds::wire_string(report.code);
  w.message = dds::wire_string(report.message);
  motion_status_.write(w);
}

void CellSimNode::publish_ground_truth(const GroundTruth& truth, WallTime stamp) {
  const auto publish = [&](const char* id, const Eigen::Isometry3d& pose) {
    rigger_vision_TrackedPose w{};
    w.header.stamp = dds::to_wire(stamp);
    w.header.frame_id = const_cast<char*>(kWorldFrame);
    w.object_id = const_cast<char*>(id);
    w.pose.pose = dds::to_wire(pose);
    w.quality = 1.0;
    w.tracked = true;
    ground_truth_.write(w);
  };
  for (const ObjectTruth& object : truth.objects) publish(object.id.c_str(), object.pose_world_object);
  // A removed object's instance is disposed: readers see it gone, not standing at its last pose.
  for (const std::string& id : truth.removed) {
    rigger_vision_TrackedPose w{};
    w.object_id = const_cast<char*>(id.c_str());
    ground_truth_.dispose(w);
  }
}

void CellSimNode::publish_status(const StatusReport& s, WallTime stamp) {
  rigger_sim_SimStatus w{};
  w.header.stamp = dds::to_wire(stamp);
  w.header.frame_id = const_cast<char*>("crane");
  w.sim_time_s = s.sim_time_s;
  w.steps = s.steps;
  w.real_time_factor_target = s.real_time_factor_target;
  w.real_time_factor_measured = s.real_time_factor_measured;
  w.overruns = s.overruns;
  w.mujoco_warnings = s.mujoco_warnings;
  w.camera_frames = s.camera_frames;
  w.camera_frames_dropped = s.camera_frames_dropped;
  w.estop_pressed = s.estop_pressed;
  w.plc_link_up = s.plc_link_up;
  w.plc_port = s.plc_port;
  w.plc_clients = static_cast<std::uint32_t>(s.plc_clients);
  w.plc_status_word = s.plc_status_word;
  w.plc_fault_code = s.plc_fault_code;
  w.plc_heartbeat = s.plc_heartbeat;
  w.plc_control_word = s.plc_control_word;
  w.gateway_heartbeat = s.gateway_heartbeat;
  copy3(s.plc_setpoint_mps, w.plc_setpoint_mps);
  copy3(s.plc_drive_command_mps, w.plc_drive_command_mps);
  copy3(s.crane_position_m, w.crane_position_m);
  copy3(s.crane_velocity_mps, w.crane_velocity_mps);
  w.crane_load_kg = s.crane_load_kg;
  w.crane_sway_rad[0] = s.crane_sway_rad[0];
  w.crane_sway_rad[1] = s.crane_sway_rad[1];
  w.gripper_holding_force_n = s.gripper_holding_force_n;
  w.load_external_force_n = dds::to_wire_vector(s.load_external_force_n);
  sim_status_.write(w);
}

void CellSimNode::publish_control_result(const ControlResult& result, WallTime stamp) {
  rigger_sim_SimEvent w{};
  w.header.stamp = dds::to_wire(stamp);
  w.control_seq = result.seq;
  w.control_source = dds::wire_string(result.source);
  w.kind = to_wire(result.kind);
  w.accepted = result.accepted;
  w.message = dds::wire_string(result.message);
  sim_event_.write(w);
}

rigger_vision_Image CellSimNode::wire_image(const cv::Mat& image, const char* encoding, WallTime stamp) const {
  rigger_vision_Image w{};
  w.header.stamp = dds::to_wire(stamp);
  w.header.frame_id = const_cast<char*>(config_.camera_id.c_str());
  w.height = static_cast<std::uint32_t>(image.rows);
  w.width = static_cast<std::uint32_t>(image.cols);
  w.encoding = const_cast<char*>(encoding);
  w.is_bigendian = false;  // 32FC1: the host's floats, and rigger runs on little-endian machines
  w.step = static_cast<std::uint32_t>(image.step[0]);
  dds::wire_buffer(w.data, image.data, image.total() * image.elemSize());
  return w;
}

CameraDemand CellSimNode::camera_demand() const {
  CameraDemand demand;
  demand.image = ros2_image_ ? ros2_image_->matched_readers() > 0 : image_->matched_readers() > 0;
  demand.depth = depth_ && depth_->matched_readers() > 0;
  return demand;
}

void CellSimNode::publish_images(const CameraImages& images, WallTime stamp) {
  const cv::Mat& image_mono8 = images.image_mono8;
  if (!image_mono8.isContinuous() || image_mono8.type() != CV_8UC1) return;  // the renderers' output is both
  // Depth first: a reader that has the image of a frame finds its depth already published.
  if (depth_ && !images.depth_m.empty() && images.depth_m.isContinuous() && images.depth_m.type() == CV_32FC1) {
    depth_->write(wire_image(images.depth_m, "32FC1", stamp));
  }
  const rigger_vision_Image w = wire_image(image_mono8, "mono8", stamp);
  if (!ros2_image_) {
    image_->write(w);
    return;
  }
  sensor_msgs_msg_dds__Image_ r{};
  r.header_ = ros2::to_ros2(w.header);
  r.height_ = w.height;
  r.width_ = w.width;
  r.encoding_ = w.encoding;
  r.is_bigendian_ = 0;
  r.step_ = w.step;
  dds::wire_buffer(r.data_, image_mono8.data, image_mono8.total());
  ros2_image_->write(r);
  // As a ROS 2 camera driver does: the intrinsics of this image, with its stamp and frame.
  rigger_vision_CameraInfo info = camera_info_wire_;
  info.header = w.header;
  ros2_camera_info_->write(ros2::to_ros2(info));
}

void CellSimNode::publish_camera_info(const sim::CameraModel& camera) {
  // plumb_bob carries five coefficients; a cell file may give four (k3 = 0) or none.
  camera_info_d_ = camera.distortion;
  camera_info_d_.resize(5, 0.0);
  rigger_vision_CameraInfo& w = camera_info_wire_;
  w.header.stamp = dds::wire_now();
  w.header.frame_id = const_cast<char*>(config_.camera_id.c_str());
  w.height = static_cast<std::uint32_t>(camera.height_px);
  w.width = static_cast<std::uint32_t>(camera.width_px);
  w.distortion_model = const_cast<char*>("plumb_bob");
  w.d = {static_cast<std::uint32_t>(camera_info_d_.size()), static_cast<std::uint32_t>(camera_info_d_.size()),
         camera_info_d_.data(), false};
  const double k[9] = {camera.fx_px, 0, camera.cx_px, 0, camera.fy_px, camera.cy_px, 0, 0, 1};
  const double r[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1};
  const double p[12] = {camera.fx_px, 0, camera.cx_px, 0, 0, camera.fy_px, camera.cy_px, 0, 0, 0, 1, 0};
  std::copy(std::begin(k), std::end(k), std::begin(w.k));
  std::copy(std::begin(r), std::end(r), std::begin(w.r));
  std::copy(std::begin(p), std::end(p), std::begin(w.p));
  // On rigger's topics once (state QoS); as a ROS 2 driver with each image instead (publish_images).
  if (camera_info_) camera_info_->write(w);
}

}  // namespace rigger::cell_sim
