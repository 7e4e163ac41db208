#include "admittance_node.hpp"

#include <cmath>
#include <limits>

#include "rigger/dds/conversions.hpp"

namespace rigger::control {

namespace {

// Node keys are read before load_control_config(), whose finish() then accepts them as read.
double read_twist_timeout(const Config& config) { return config.get_in_range("twist_timeout_s", 0.05, 0.002, 1.0); }
double read_crane_timeout(const Config& config) { return config.get_in_range("crane_timeout_s", 0.2, 0.02, 2.0); }

std::chrono::nanoseconds period_of(double rate_hz) { return from_seconds(1.0 / rate_hz); }

// The age of a wire stamp now; an absent stamp is infinitely old (the laws then report it stale).
Seconds age_of(const std::optional<WallTime>& stamp) {
  if (!stamp) return Seconds(std::numeric_limits<double>::infinity());
  return std::chrono::duration_cast<Seconds>(std::chrono::system_clock::now() - *stamp);
}

std::optional<Vector6d> gains_vector(const dds_sequence_double& seq) {
  if (seq._length != 6) return std::nullopt;
  Vector6d v;
  for (int i = 0; i < 6; ++i) v(i) = seq._buffer[i];
  return v;
}

}  // namespace

AdmittanceNode::AdmittanceNode(dds::ServiceContext& ctx)
    : ctx_(ctx),
      twist_timeout_s_(read_twist_timeout(ctx.config)),
      crane_timeout_s_(read_crane_timeout(ctx.config)),
      config_(load_control_config(ctx.config)),
      robot_(config_.robot),
      crane_(config_.crane),
      wrenches_(ctx.participant, kWrenchTopic, dds::qos::sensor_stream()),
      robot_states_(ctx.participant, kRobotStateTopic, dds::qos::sensor_stream()),
      commands_(ctx.participant, kCommandTopic, dds::qos::commands()),
      joystick_(ctx.participant, kJoystickTopic, dds::qos::setpoints()),
      tracker_poses_(ctx.participant, kTrackerPoseTopic, dds::qos::sensor_stream()),
      cmd_twist_(ctx.participant, kCmdTwistTopic, dds::qos::setpoints()),
      crane_cmd_(ctx.participant, kCraneCmdTopic, dds::qos::setpoints()),
      state_(ctx.participant, kStateTopic, dds::qos::state()) {
  ctx.loop.on_data(wrenches_, [this] { on_wrench(); });
  ctx.loop.on_data(robot_states_, [this] { on_robot_state(); });
  ctx.loop.on_data(commands_, [this] { on_command(); });
  ctx.loop.on_data(joystick_, [this] { on_joystick(); });
  ctx.loop.on_data(tracker_poses_, [this] { on_tracker_pose(); });
  ctx.loop.every(period_of(config_.robot_rate_hz), [this] { robot_step(); });
  ctx.loop.every(period_of(config_.crane_rate_hz), [this] { crane_step(); });
  publish_state();
  ctx.log->info("robot loop {} Hz, crane loop {} Hz, mode OFF", config_.robot_rate_hz, config_.crane_rate_hz);
}

AdmittanceNode::~AdmittanceNode() {
  // Setpoints time out at the consumers anyway; an explicit zero stops them at once.
  if (robot_published_) publish_twist(Vector6d::Zero());
  if (crane_published_) publish_crane(Eigen::Vector3d::Zero());
}

void AdmittanceNode::on_wrench() {
  wrenches_.take([this](const rigger_sensing_WrenchStamped& w, const dds_sample_info_t&) {
    // Non-finite values go to the law as they are: it faults (WRENCH_NOT_FINITE), never "zero force".
    wrench_sensor_ = Wrench::from_stacked(dds::to_domain(w.wrench));
    wrench_stamp_ = dds::to_domain(w.header.stamp);
  });
}

void AdmittanceNode::on_robot_state() {
  robot_states_.take([this](const rigger_robot_RobotState& s, const dds_sample_info_t&) {
    // The F/T sensor sits on the flange: its orientation is the flange's. The raw quaternion is
    // passed on (not normalised) so that the law can refuse an invalid one (ORIENTATION_INVALID).
    const auto& q = s.flange_pose.orientation;
    orientation_base_sensor_ = Eigen::Quaterniond(q.w, q.x, q.y, q.z);
  });
}

void AdmittanceNode::on_joystick() {
  joystick_.take([this](const rigger_sensing_TwistCommand& t, const dds_sample_info_t&) {
    joystick_twist_ = Twist::from_stacked(dds::to_domain(t.twist));
    joystick_stamp_ = dds::to_domain(t.header.stamp);
  });
}

void AdmittanceNode::on_tracker_pose() {
  // The visual-servo reference is not wired into the node yet (see README): poses are taken so the
  // reader does not keep waking the loop.
  tracker_poses_.take([](const rigger_vision_TrackedPose&, const dds_sample_info_t&) {});
}

void AdmittanceNode::on_command() {
  commands_.take([this](const rigger_admittance_AdmittanceCommand& c, const dds_sample_info_t&) {
    last_command_seq_ = c.seq;
    const std::string source = dds::to_string(c.source);
    AdmittanceMode mode;
    switch (c.mode) {
      case rigger_admittance_ADMITTANCE_OFF: mode = AdmittanceMode::kOff; break;
      case rigger_admittance_ADMITTANCE_ROBOT: mode = AdmittanceMode::kRobot; break;
      case rigger_admittance_ADMITTANCE_ROBOT_AND_CRANE: mode = AdmittanceMode::kRobotAndCrane; break;
      default:
        ctx_.log->warn("command refused seq={} source={}: unknown mode {}", c.seq, source, static_cast<int>(c.mode));
        return;
    }
    ReferenceSource reference;
    switch (c.reference) {
      case rigger_admittance_REFERENCE_NONE: reference = ReferenceSource::kNone; break;
      case rigger_admittance_REFERENCE_JOYSTICK: reference = ReferenceSource::kJoystick; break;
      case rigger_admittance_REFERENCE_VISUAL_SERVO: reference = ReferenceSource::kVisualServo; break;
      default:
        ctx_.log->warn("command refused seq={} source={}: unknown reference {}", c.seq, source,
                       static_cast<int>(c.reference));
        return;
    }
    // Gains: each sequence is empty (keep) or six values; all-or-nothing.
    const auto bad_length = [](std::uint32_t n) { return n != 0 && n != 6; };
    if (bad_length(c.mass._length) || bad_length(c.damping._length) || bad_length(c.stiffness._length) ||
        (c.axes._length != 0 && c.axes._length != 6)) {
      ctx_.log->warn("command refused seq={} source={}: mass, damping, stiffness and axes need 0 or 6 values",
                     c.seq, source);
      return;
    }
    if (c.mass._length || c.damping._length || c.stiffness._length) {
      AdmittanceGains gains = robot_.target_gains();
      if (auto v = gains_vector(c.mass)) gains.mass = *v;
      if (auto v = gains_vector(c.damping)) gains.damping = *v;
      if (auto v = gains_vector(c.stiffness)) gains.stiffness = *v;
      const RequestResult result = robot_.set_gains(gains);
      if (!result.accepted) {
        ctx_.log->warn("command refused seq={} source={}: gains: {}", c.seq, source, result.reason);
        return;
      }
    }
    if (c.axes._length == 6) {
      std::array<bool, 6> axes{};
      for (std::size_t i = 0; i < 6; ++i) axes[i] = c.axes._buffer[i];
      robot_.set_selected_axes(axes);
    }
    if (reference == ReferenceSource::kVisualServo) {
      ctx_.log->warn("command seq={}: the visual-servo reference is not available in this node yet; no reference",
                     c.seq);
    }
    mode_ = mode;
    reference_ = reference;
    robot_.set_reference_source(reference);
    robot_.set_mode(mode);  // also acknowledges a latched fault
    crane_.set_enabled(mode == AdmittanceMode::kRobotAndCrane);
    ctx_.log->info("command seq={} source={} mode={} reference={}", c.seq, source, to_string(mode),
                   to_string(reference));
    publish_state();
  });
}

void AdmittanceNode::robot_step() {
  const auto now = dds::EventLoop::Clock::now();
  const Seconds dt = last_robot_step_ ? std::chrono::duration_cast<Seconds>(now - *last_robot_step_)
                                      : std::chrono::duration_cast<Seconds>(period_of(config_.robot_rate_hz));
  last_robot_step_ = now;

  ReferenceInput reference;
  if (reference_ == ReferenceSource::kJoystick && joystick_stamp_) {
    reference.source = ReferenceSource::kJoystick;
    reference.twist = joystick_twist_;
    reference.frame = ControlFrame::kBase;
    reference.age = age_of(joystick_stamp_);
  }
  if (!orientation_base_sensor_) {
    // Without the sensor's orientation the wrench cannot be turned into the base frame: zero.
    robot_output_ = AdmittanceOutput{};
    if (mode_ != AdmittanceMode::kOff) publish_twist(Vector6d::Zero());
  } else {
    robot_output_ = robot_.step(dt, WrenchSample{wrench_sensor_, age_of(wrench_stamp_)}, *orientation_base_sensor_,
                                reference);
    Twist twist = robot_output_.twist;
    if (robot_output_.frame == ControlFrame::kTool) twist = rotate(orientation_base_sensor_->normalized().toRotationMatrix(), twist);
    if (robot_output_.status.state != AdmittanceState::kOff) {
      publish_twist(twist.stacked());
    } else if (robot_published_) {
      publish_twist(Vector6d::Zero());  // once, on reaching OFF
      robot_published_ = false;
    }
  }
  if (fault_code() != last_fault_code_) publish_state();
}

void AdmittanceNode::crane_step() {
  const auto now = dds::EventLoop::Clock::now();
  const Seconds dt = last_crane_step_ ? std::chrono::duration_cast<Seconds>(now - *last_crane_step_)
                                      : std::chrono::duration_cast<Seconds>(period_of(config_.crane_rate_hz));
  last_crane_step_ = now;
  CraneInput input;
  // Base orientation = world orientation (see the header), so base-frame vectors are world vectors.
  input.force_on_robot_world_n = robot_output_.wrench_base.force_n;
  input.force_age = orientation_base_sensor_ ? age_of(wrench_stamp_) : Seconds(std::numeric_limits<double>::infinity());
  input.robot_velocity_world_mps = robot_output_.twist.linear_mps;
  crane_output_ = crane_.step(dt, input);
  if (crane_output_.status.state != CraneState::kDisabled) {
    publish_crane(crane_output_.velocity_world_mps);
  } else if (crane_published_) {
    publish_crane(Eigen::Vector3d::Zero());  // once, on reaching DISABLED
    crane_published_ = false;
  }
  publish_state();
}

void AdmittanceNode::publish_twist(const Vector6d& twist_base) {
  rigger_sensing_TwistCommand out{};
  out.header.stamp = dds::wire_now();
  out.header.frame_id = const_cast<char*>("base");
  out.seq = ++twist_seq_;
  out.twist = dds::to_wire_twist(twist_base);
  out.timeout_s = twist_timeout_s_;
  out.source = dds::wire_string(ctx_.options.id);
  cmd_twist_.write(out);
  robot_published_ = true;
}

void AdmittanceNode::publish_crane(const Eigen::Vector3d& velocity_world_mps) {
  // to_crane_axes() gives the hoist as rope-length rate (positive lowers); the wire (idl/crane.idl)
  // carries hook height, up positive: negate the hoist component.
  const std::array<double, 3> axes = to_crane_axes(velocity_world_mps);
  rigger_crane_CraneVelocityCommand out{};
  out.header.stamp = dds::wire_now();
  out.header.frame_id = const_cast<char*>("world");
  out.seq = ++crane_seq_;
  out.velocity_mps[0] = axes[0];
  out.velocity_mps[1] = axes[1];
  out.velocity_mps[2] = -axes[2];
  out.timeout_s = crane_timeout_s_;
  out.source = dds::wire_string(ctx_.options.id);
  crane_cmd_.write(out);
  crane_published_ = true;
}

std::string AdmittanceNode::fault_code() const {
  if (mode_ == AdmittanceMode::kOff) return "";
  if (!orientation_base_sensor_) return kFaultNoRobotState;
  if (robot_output_.status.fault != AdmittanceFault::kNone) return std::string(to_string(robot_output_.status.fault));
  if (crane_output_.status.fault != CraneFault::kNone) return std::string(to_string(crane_output_.status.fault));
  return "";
}

void AdmittanceNode::publish_state() {
  const std::string code = fault_code();
  last_fault_code_ = code;
  rigger_admittance_AdmittanceState out{};
  out.header.stamp = dds::wire_now();
  out.header.frame_id = const_cast<char*>("base");
  out.mode = mode_ == AdmittanceMode::kOff     ? rigger_admittance_ADMITTANCE_OFF
             : mode_ == AdmittanceMode::kRobot ? rigger_admittance_ADMITTANCE_ROBOT
                                               : rigger_admittance_ADMITTANCE_ROBOT_AND_CRANE;
  out.reference = reference_ == ReferenceSource::kNone       ? rigger_admittance_REFERENCE_NONE
                  : reference_ == ReferenceSource::kJoystick ? rigger_admittance_REFERENCE_JOYSTICK
                                                             : rigger_admittance_REFERENCE_VISUAL_SERVO;
  out.fault = !code.empty();
  out.fault_code = dds::wire_string(code);
  std::string text;
  if (code == kFaultNoRobotState) text = "no rigger/robot/state received yet";
  else if (!code.empty()) text = "output is zero";
  out.fault_text = dds::wire_string(text);
  out.filtered_wrench = dds::to_wire_wrench(robot_output_.wrench_applied.stacked());
  out.robot_twist = dds::to_wire_twist(robot_output_.twist.stacked());
  out.crane_velocity = dds::to_wire_vector(crane_output_.velocity_world_mps);
  out.last_command_seq = last_command_seq_;
  state_.write(out);
}

}  // namespace rigger::control
