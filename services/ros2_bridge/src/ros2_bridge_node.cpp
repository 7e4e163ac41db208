#include "ros2_bridge_node.hpp"

#include <algorithm>

#include "rigger/dds/conversions.hpp"
#include "rigger/dds/sequences.hpp"
#include "rigger/protocol/robot.hpp"
#include "rigger/protocol/vision.hpp"
#include "rigger/ros2/conversions.hpp"
#include "rigger/ros2/qos.hpp"

namespace rigger::ros2_bridge {
namespace {

dds::Qos qos_of(Ros2Qos qos) {
  switch (qos) {
    case Ros2Qos::kSensorData:
      return ros2::qos::sensor_data();
    case Ros2Qos::kReliableDefault:
      return ros2::qos::reliable_default();
    case Ros2Qos::kSystemDefault:
      break;
  }
  return ros2::qos::system_default();
}

}  // namespace

Ros2BridgeNode::Ros2BridgeNode(service::ServiceContext& ctx) : ctx_(ctx), config_(read_bridge_config(ctx.config)) {
  ctx.config.finish();
  if (config_.image) {
    const ImageStream& i = *config_.image;
    rigger_image_.emplace(ctx.participant, protocol::vision::kCameraImage);
    ros2_image_.emplace(ctx.participant, i.dds_topic, qos_of(i.qos));
    ctx.loop.on_data(*ros2_image_, [this] { on_ros2_image(); });
    ctx.log->info("bridging image from={} dds_topic={} qos={} to={} as mono8 max_age_s={}", i.ros_topic, i.dds_topic,
                  ros2_qos_name(i.qos), protocol::vision::kCameraImage.name, to_seconds(i.age.max_age));
    rigger_camera_info_.emplace(ctx.participant, protocol::vision::kCameraInfo);
    ros2_camera_info_.emplace(ctx.participant, i.camera_info_dds_topic, qos_of(i.qos));
    ctx.loop.on_data(*ros2_camera_info_, [this] { on_ros2_camera_info(); });
    ctx.log->info("bridging camera_info from={} dds_topic={} to={} when it changes", i.camera_info_ros_topic,
                  i.camera_info_dds_topic, protocol::vision::kCameraInfo.name);
  }
  if (config_.wrench) {
    const WrenchStream& w = *config_.wrench;
    rigger_wrench_.emplace(ctx.participant, protocol::robot::kWrench);
    ros2_wrench_.emplace(ctx.participant, w.dds_topic, qos_of(w.qos));
    ctx.loop.on_data(*ros2_wrench_, [this] { on_ros2_wrench(); });
    ctx.log->info("bridging wrench from={} dds_topic={} qos={} to={} max_age_s={}", w.ros_topic, w.dds_topic,
                  ros2_qos_name(w.qos), protocol::robot::kWrench.name, to_seconds(w.age.max_age));
  }
  if (config_.joint_states) {
    const JointStatesStream& j = *config_.joint_states;
    joint_map_.emplace(j.joints, j.ignore_joints);
    rigger_state_.emplace(ctx.participant, protocol::robot::kState);
    ros2_joint_states_.emplace(ctx.participant, j.dds_topic, qos_of(j.qos));
    ctx.loop.on_data(*ros2_joint_states_, [this] { on_ros2_joint_states(); });
    ctx.log->info("bridging joint_states from={} dds_topic={} qos={} to={} joints={} frame_id={} max_age_s={}",
                  j.ros_topic, j.dds_topic, ros2_qos_name(j.qos), protocol::robot::kState.name, j.joints.size(),
                  j.frame_id, to_seconds(j.age.max_age));
  }
  if (config_.twist) {
    const TwistStream& t = *config_.twist;
    ros2_twist_.emplace(ctx.participant, t.dds_topic, qos_of(t.qos));
    rigger_twist_.emplace(ctx.participant, protocol::robot::kCmdTwist);
    ctx.loop.on_data(*rigger_twist_, [this] { on_rigger_twist(); });
    // The bridge is the robot's motion input as far as rigger can reach: it obeys the robot's safe stop.
    safe_stop_.emplace(ctx.participant, ctx.loop, std::vector<std::string>{"robot"},
                       [this](const std::string&, const safety::StopState& stop) { on_safe_stop(stop); });
    ctx.log->info(
        "bridging twist_command from={} to={} dds_topic={} qos={} max_age_s={} max_linear_mps={} "
        "max_angular_radps={} over_limit={}",
        protocol::robot::kCmdTwist.name, t.ros_topic, t.dds_topic, ros2_qos_name(t.qos), to_seconds(t.age.max_age),
        t.limits.max_linear_mps, t.limits.max_angular_radps,
        t.limits.over_limit == OverLimit::kClamp ? "clamp" : "refuse");
  }
}

void Ros2BridgeNode::on_ros2_image() {
  const ImageStream& cfg = *config_.image;
  ros2_image_->take([&](const sensor_msgs_msg_dds__Image_& in, const dds_sample_info_t&) {
    const rigger_geometry_Header header = ros2::to_rigger(in.header_);
    if (!fresh("image", header.stamp, cfg.age)) return;
    const std::string encoding = in.encoding_ == nullptr ? "" : in.encoding_;
    const auto data = dds::elements(in.data_);
    const ImageVerdict verdict = to_mono8(encoding, in.width_, in.height_, in.step_, data.data(), data.size(), grey_);
    if (verdict != ImageVerdict::kOk) {
      count("dropped", "image", image_verdict_name(verdict),
            fmt::format("encoding={} width={} height={} step={} bytes={}", encoding, in.width_, in.height_, in.step_,
                        data.size()));
      return;
    }
    rigger_vision_Image out{};
    out.header = header;
    if (!cfg.frame_id.empty()) out.header.frame_id = dds::wire_string(cfg.frame_id);
    out.width = in.width_;
    out.height = in.height_;
    out.encoding = const_cast<char*>("mono8");
    out.step = in.width_;
    dds::wire_sequence(out.data, grey_);
    if (rigger_image_->write(out) == DDS_RETCODE_OK) ++image_forwarded_;
  });
}

void Ros2BridgeNode::on_ros2_camera_info() {
  const ImageStream& cfg = *config_.image;
  ros2_camera_info_->take([&](const sensor_msgs_msg_dds__CameraInfo_& in, const dds_sample_info_t&) {
    if (!fresh("camera_info", ros2::to_rigger(in.header_.stamp_), cfg.age)) return;
    const auto d = dds::elements(in.d_);
    CameraInfoFields fields;
    fields.distortion_model = in.distortion_model_ == nullptr ? "" : in.distortion_model_;
    fields.d = d.data();
    fields.d_count = d.size();
    fields.k = in.k_;
    fields.p = in.p_;
    fields.width = in.width_;
    fields.height = in.height_;
    fields.binning_x = in.binning_x_;
    fields.binning_y = in.binning_y_;
    fields.roi_x = in.roi_.x_offset_;
    fields.roi_y = in.roi_.y_offset_;
    fields.roi_width = in.roi_.width_;
    fields.roi_height = in.roi_.height_;
    const CameraInfoVerdict verdict = check_camera_info(fields);
    if (verdict != CameraInfoVerdict::kOk) {
      count("dropped", "camera_info", camera_info_verdict_name(verdict),
            fmt::format("distortion_model={} coefficients={} width={} height={} binning={}x{}", fields.distortion_model,
                        d.size(), in.width_, in.height_, in.binning_x_, in.binning_y_));
      return;
    }
    rigger_vision_CameraInfo out = ros2::to_rigger(in);
    if (!cfg.frame_id.empty()) out.header.frame_id = const_cast<char*>(cfg.frame_id.c_str());
    std::vector<double> coefficients(d.begin(), d.end());
    coefficients.resize(5, 0.0);  // rigger's plumb_bob: k1 k2 p1 p2 k3, k3 = 0 when left out
    out.distortion_model = const_cast<char*>("plumb_bob");
    out.d = {5, 5, coefficients.data(), false};
    // A driver repeats its intrinsics with every image; rigger/camera/info is state: written when they change.
    std::vector<std::uint8_t> key;
    const auto add = [&key](const void* bytes, std::size_t n) {
      key.insert(key.end(), static_cast<const std::uint8_t*>(bytes), static_cast<const std::uint8_t*>(bytes) + n);
    };
    const std::string frame = out.header.frame_id == nullptr ? "" : out.header.frame_id;
    add(frame.data(), frame.size() + 1);
    add(&out.width, sizeof out.width);
    add(&out.height, sizeof out.height);
    add(coefficients.data(), coefficients.size() * sizeof(double));
    add(out.k, sizeof out.k);
    add(out.r, sizeof out.r);
    add(out.p, sizeof out.p);
    if (key == last_camera_info_) return;
    if (rigger_camera_info_->write(out) == DDS_RETCODE_OK) {
      last_camera_info_ = std::move(key);
      ++camera_info_forwarded_;
    }
  });
}

Ros2BridgeNode::~Ros2BridgeNode() {
  if (hold_timer_) send_zero_twist("bridge stopping");
  ctx_.log->info(
      "bridge stopped wrench_forwarded={} twist_forwarded={} image_forwarded={} camera_info_forwarded={} "
      "state_forwarded={}",
      wrench_forwarded_, twist_forwarded_, image_forwarded_, camera_info_forwarded_, state_forwarded_);
}

bool Ros2BridgeNode::fresh(const std::string& stream, const rigger_geometry_Time& wire_stamp, const AgeLimits& limits) {
  const WallTime stamp = dds::to_domain(wire_stamp);
  const WallTime now = std::chrono::system_clock::now();
  const AgeVerdict age = check_age(stamp, now, limits);
  if (age == AgeVerdict::kFresh) return true;
  count("dropped", stream, age_verdict_name(age),
        fmt::format("age_s={:.3f} max_age_s={}", to_seconds(now - stamp), to_seconds(limits.max_age)));
  return false;
}

void Ros2BridgeNode::count(std::string_view event, const std::string& stream, std::string_view reason,
                           const std::string& detail) {
  const std::string key = stream + " " + std::string(reason);
  auto it = refusals_.try_emplace(key, config_.refusal_log_interval).first;
  if (it->second.count(std::chrono::steady_clock::now())) {
    ctx_.log->warn("{} {} reason={} count={} total={} {}", event, stream, reason, it->second.batch(),
                   it->second.total(), detail);
  }
}

void Ros2BridgeNode::on_ros2_wrench() {
  const WrenchStream& cfg = *config_.wrench;
  ros2_wrench_->take([&](const geometry_msgs_msg_dds__WrenchStamped_& in, const dds_sample_info_t&) {
    rigger_sensing_WrenchStamped out = ros2::to_rigger(in);
    if (!fresh("wrench", out.header.stamp, cfg.age)) return;
    if (!all_finite(dds::to_domain(out.wrench))) {
      count("dropped", "wrench", "not_finite", "");
      return;
    }
    if (!cfg.frame_id.empty()) out.header.frame_id = dds::wire_string(cfg.frame_id);
    if (rigger_wrench_->write(out) == DDS_RETCODE_OK) ++wrench_forwarded_;
  });
}

// JointState gives joints only: poses and twist come from the configured kinematics; `mode` says whether the
// bridge is holding a twist command it forwarded (ROBOT_VELOCITY) or not (ROBOT_IDLE); `fault` stays empty
// (a driver's faults are not on /joint_states). docs/ros2.md says so.
void Ros2BridgeNode::on_ros2_joint_states() {
  const JointStatesStream& cfg = *config_.joint_states;
  ros2_joint_states_->take([&](const sensor_msgs_msg_dds__JointState_& in, const dds_sample_info_t&) {
    const rigger_geometry_Header header = ros2::to_rigger(in.header_);
    if (!fresh("joint_states", header.stamp, cfg.age)) return;
    joint_names_.clear();
    for (const char* name : dds::elements(in.name_)) joint_names_.emplace_back(name == nullptr ? "" : name);
    const auto positions = dds::elements(in.position_);
    const auto velocities = dds::elements(in.velocity_);
    const ChainJoints joints =
        joint_map_->map(joint_names_, positions.data(), positions.size(), velocities.data(), velocities.size());
    if (joints.verdict != JointStateVerdict::kOk) {
      count("dropped", "joint_states", joint_state_verdict_name(joints.verdict), joints.detail);
      return;
    }
    const ArmState arm = cfg.kinematics->evaluate(joints.position_rad, joints.velocity_radps, cfg.pose_flange_tool);
    std::vector<double> position(joints.position_rad.data(), joints.position_rad.data() + joints.position_rad.size());
    std::vector<double> velocity(joints.velocity_radps.data(),
                                 joints.velocity_radps.data() + joints.velocity_radps.size());
    Vector6d twist;
    twist << arm.tool_linear_mps, arm.tool_angular_radps;
    rigger_robot_RobotState out{};
    out.header.stamp = header.stamp;
    out.header.frame_id = dds::wire_string(cfg.frame_id);
    out.mode = hold_timer_ ? rigger_robot_ROBOT_VELOCITY : rigger_robot_ROBOT_IDLE;
    dds::wire_sequence(out.joint_position, position);
    dds::wire_sequence(out.joint_velocity, velocity);
    out.flange_pose = dds::to_wire(arm.pose_base_flange);
    out.tool_pose = dds::to_wire(arm.pose_base_tool);
    out.tool_twist = dds::to_wire_twist(twist);
    out.moving = joints.velocity_radps.cwiseAbs().maxCoeff() > cfg.moving_threshold_radps;
    out.fault = dds::wire_string("");
    out.last_command_seq = last_twist_seq_;
    if (rigger_state_->write(out) == DDS_RETCODE_OK) ++state_forwarded_;
  });
}

void Ros2BridgeNode::on_rigger_twist() {
  const TwistStream& cfg = *config_.twist;
  rigger_twist_->take([&](const rigger_sensing_TwistCommand& in, const dds_sample_info_t&) {
    if (safe_stop_->active()) {
      count("dropped", "twist_command", "safe_stop",
            fmt::format("seq={} source={} stop=\"{}\"", in.seq, dds::to_string(in.source), safe_stop_->describe()));
      return;
    }
    const WallTime stamp = dds::to_domain(in.header.stamp);
    const WallTime now = std::chrono::system_clock::now();
    const AgeVerdict age = check_age(stamp, now, cfg.age);
    if (age != AgeVerdict::kFresh) {
      count("dropped", "twist_command", age_verdict_name(age),
            fmt::format("seq={} source={} age_s={:.3f} max_age_s={}", in.seq, dds::to_string(in.source),
                        to_seconds(now - stamp), to_seconds(cfg.age.max_age)));
      return;
    }
    const Vector6d requested = dds::to_domain(in.twist);
    const LimitedTwist limited = limit_twist(requested, cfg.limits);
    if (!limited.send()) {
      count("dropped", "twist_command", twist_verdict_name(limited.verdict),
            fmt::format("seq={} source={} linear_mps={:.3f} angular_radps={:.3f} max_linear_mps={} "
                        "max_angular_radps={}",
                        in.seq, dds::to_string(in.source), requested.head<3>().norm(), requested.tail<3>().norm(),
                        cfg.limits.max_linear_mps, cfg.limits.max_angular_radps));
      return;
    }
    if (limited.verdict == TwistVerdict::kClamped) {
      count("clamped", "twist_command", "over_limit",
            fmt::format("seq={} source={} linear_mps={:.3f} angular_radps={:.3f}", in.seq, dds::to_string(in.source),
                        requested.head<3>().norm(), requested.tail<3>().norm()));
    }
    rigger_geometry_Header header = in.header;
    if (!cfg.frame_id.empty()) header.frame_id = dds::wire_string(cfg.frame_id);
    const rigger_geometry_Twist twist = dds::to_wire_twist(limited.twist);
    if (ros2_twist_->write(ros2::to_ros2_twist_stamped(header, twist)) != DDS_RETCODE_OK) return;
    ++twist_forwarded_;
    last_twist_seq_ = in.seq;
    zero_frame_id_ = dds::to_string(header.frame_id);
    // Hold the command for its own timeout (capped), then stop the driver explicitly.
    const auto hold = in.timeout_s > 0.0 ? std::min(from_seconds(in.timeout_s), cfg.max_hold) : cfg.max_hold;
    if (hold_timer_) ctx_.loop.cancel(*hold_timer_);
    hold_timer_ = ctx_.loop.after(hold, [this] {
      hold_timer_.reset();
      send_zero_twist("command timeout");
    });
  });
}

void Ros2BridgeNode::on_safe_stop(const safety::StopState& stop) {
  if (!stop.active) {
    ctx_.log->warn("safe stop reset robot by={} reason=\"{}\": twist commands forwarded again", stop.source,
                   stop.reason);
    return;
  }
  ctx_.log->error("SAFE_STOP robot by={} reason=\"{}\": zero twist sent, twist commands dropped until reset",
                  stop.source, stop.reason);
  if (hold_timer_) ctx_.loop.cancel(*hold_timer_);
  hold_timer_.reset();
  send_zero_twist("safe stop by " + stop.source);
}

void Ros2BridgeNode::send_zero_twist(const std::string& why) {
  rigger_geometry_Header header{dds::wire_now(), dds::wire_string(zero_frame_id_)};
  const rigger_geometry_Twist zero = dds::to_wire_twist(Vector6d::Zero());
  const dds_return_t rc = ros2_twist_->write(ros2::to_ros2_twist_stamped(header, zero));
  ctx_.log->info("zero twist sent reason=\"{}\" rc={}", why, rc);
}

}  // namespace rigger::ros2_bridge
