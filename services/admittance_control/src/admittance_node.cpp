#include "admittance_node.hpp"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <limits>

#include "rigger/base/install.hpp"
#include "rigger/cell_config/cell_file.hpp"
#include "rigger/dds/conversions.hpp"
#include "rigger/dds/sequences.hpp"
#include "rigger/protocol/admittance.hpp"
#include "rigger/protocol/crane.hpp"
#include "rigger/protocol/operator.hpp"
#include "rigger/protocol/robot.hpp"
#include "rigger/protocol/vision.hpp"

namespace rigger::control {

namespace {

// The robot base's pose in the world: entity `robot_id` of the configured cell file, else identity.
Eigen::Isometry3d read_pose_world_base(const Config& config, const ControlConfig& control) {
  if (!control.cell_file) return Eigen::Isometry3d::Identity();
  try {
    return entity_pose_from_cell_file(control.cell_file->string(), control.robot_id);
  } catch (const ConfigError& e) {
    throw ConfigError(config.file(), config.pointer() + "/cell_file", e.what());
  }
}

// With crane.rope_offset_gain_per_s > 0: the rope_object's rope attachment from the cell file.
std::optional<Eigen::Isometry3d> read_rope_attachment(const Config& config, const ControlConfig& control) {
  if (control.crane.rope_offset_gain_per_s <= 0.0) return std::nullopt;
  const std::optional<std::filesystem::path>& path = control.cell_file;
  const std::string& object = control.rope_object;
  const std::string key = config.pointer() + "/crane/rope_offset_gain_per_s";
  if (!path)
    throw ConfigError(config.file(), key,
                      "a measured rope offset needs cell_file (the rope attachment of '" + object +
                          "'); set 0 or give the cell file");
  cell::CellFile cell;
  try {
    cell = cell::load_cell_file(*path);
  } catch (const cell::CellFileError& e) {
    throw ConfigError(config.file(), config.pointer() + "/cell_file", e.what());
  }
  try {
    return rope_attachment_in_cell(cell, path->string(), object);
  } catch (const ConfigError& e) {
    throw ConfigError(config.file(), config.pointer() + "/rope_object", e.what());
  }
}

std::chrono::nanoseconds period_of(double rate_hz) {
  return from_seconds(1.0 / rate_hz);
}

// The age of a wire stamp now; an absent stamp is infinitely old (the laws then report it stale).
Seconds age_of(const std::optional<WallTime>& stamp) {
  if (!stamp) return Seconds(std::numeric_limits<double>::infinity());
  return std::chrono::duration_cast<Seconds>(std::chrono::system_clock::now() - *stamp);
}

/// Six gains from a wire sequence of doubles, nullopt when it holds another number of values.
template <typename Seq>
std::optional<Vector6d> gains_vector(const Seq& seq) {
  const auto values = dds::elements(seq);
  if (values.size() != 6) return std::nullopt;
  Vector6d v;
  for (int i = 0; i < 6; ++i) v(i) = values[i];
  return v;
}

}  // namespace

AdmittanceNode::AdmittanceNode(service::ServiceContext& ctx)
    : ctx_(ctx),
      config_(load_control_config(ctx.config)),
      twist_timeout_s_(config_.twist_timeout_s),
      crane_timeout_s_(config_.crane_timeout_s),
      pose_world_base_(read_pose_world_base(ctx.config, config_)),
      robot_id_(config_.robot_id),
      crane_state_timeout_(config_.crane_state_timeout_s),
      commander_grace_(config_.commander_grace_s),
      rope_object_(config_.rope_object),
      rope_offset_max_age_(config_.rope_offset_max_age_s),
      pose_rope_attachment_(read_rope_attachment(ctx.config, config_)),
      robot_(config_.robot),
      crane_(config_.crane),
      wrenches_(ctx.participant, protocol::robot::kWrench),
      robot_states_(ctx.participant, protocol::robot::kState),
      commands_(ctx.participant, protocol::admittance::kCommand),
      joystick_(ctx.participant, protocol::operator_ui::kJoystick),
      tracker_poses_(ctx.participant, protocol::vision::kTrackerPose),
      crane_states_(ctx.participant, protocol::crane::kState),
      directory_(ctx.participant),
      cmd_twist_(ctx.participant, protocol::robot::kCmdTwist),
      crane_cmd_(ctx.participant, protocol::crane::kCmdVelocity),
      state_(ctx.participant, protocol::admittance::kState),
      // A safe stop of anything this node moves turns it OFF (robot and crane ramp to zero) and keeps it
      // OFF until the reset: commands to turn it on are refused meanwhile.
      safe_stop_(ctx.participant, ctx.loop, {"robot", "crane", "admittance"},
                 [this](const std::string& resource, const safety::StopState& s) {
                   if (s.active) go_off(kFaultSafeStop, resource + " stopped by " + s.source + ": " + s.reason);
                 }) {
  ctx.loop.on_data(wrenches_, [this] { on_wrench(); });
  ctx.loop.on_data(robot_states_, [this] { on_robot_state(); });
  ctx.loop.on_data(commands_, [this] { on_command(); });
  ctx.loop.on_data(joystick_, [this] { on_joystick(); });
  ctx.loop.on_data(tracker_poses_, [this] { on_tracker_pose(); });
  ctx.loop.on_data(crane_states_, [this] { on_crane_state(); });
  ctx.loop.on_data(directory_.reader(), [this] { on_directory(); });
  if (config_.cell_file) {
    follower_ = std::make_unique<cell_follower::CellFollower>(
        ctx.participant, ctx.loop, ctx.log, *config_.cell_file,
        [this](const cell_follower::FollowedRevision& revision) { return on_revision(revision); }, &ctx.announcer);
  }
  ctx.loop.every(period_of(config_.robot_rate_hz), [this] { robot_step(); });
  ctx.loop.every(period_of(config_.crane_rate_hz), [this] { crane_step(); });
  publish_state();
  const Eigen::Vector3d rpy = pose_world_base_.linear().eulerAngles(2, 1, 0).reverse() * 180.0 / kPi;
  ctx.log->info(
      "robot loop {} Hz, crane loop {} Hz, mode OFF; robot base '{}' in the world at ({}, {}, {}) m, "
      "rpy ({:.1f}, {:.1f}, {:.1f}) deg",
      config_.robot_rate_hz, config_.crane_rate_hz, robot_id_, pose_world_base_.translation().x(),
      pose_world_base_.translation().y(), pose_world_base_.translation().z(), rpy.x(), rpy.y(), rpy.z());
}

cell_follower::Outcome AdmittanceNode::on_revision(const cell_follower::FollowedRevision& revision) {
  const std::string source = config_.cell_file->string();
  Eigen::Isometry3d base;
  std::optional<Eigen::Isometry3d> rope;
  try {
    base = entity_pose_in_cell(revision.cell, source, robot_id_);
    if (pose_rope_attachment_) rope = rope_attachment_in_cell(revision.cell, source, rope_object_);
  } catch (const ConfigError& e) {
    return cell_follower::Outcome::refuse(e.what());
  }
  const bool same = base.matrix() == pose_world_base_.matrix() &&
                    (!rope || rope->matrix() == pose_rope_attachment_->matrix());
  if (same) return cell_follower::Outcome::take();
  if (mode_ != AdmittanceMode::kOff) {
    return cell_follower::Outcome::refuse(
        "admittance is on (mode " + std::string(to_string(mode_)) + ") and the revision moves the robot base '" +
        robot_id_ + "' or the rope attachment of '" + rope_object_ +
        "': a running law's commands would jump; apply it again when admittance is off");
  }
  pose_world_base_ = base;
  pose_rope_attachment_ = rope;
  const Eigen::Vector3d p = base.translation();
  ctx_.log->info("cell revision {}: robot base '{}' at ({}, {}, {}) m", revision.revision, robot_id_, p.x(), p.y(),
                 p.z());
  return cell_follower::Outcome::take();
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
    tcp_position_base_ = dds::to_domain(s.tool_pose.position);
  });
}

void AdmittanceNode::on_joystick() {
  joystick_.take([this](const rigger_sensing_TwistCommand& t, const dds_sample_info_t&) {
    joystick_twist_ = Twist::from_stacked(dds::to_domain(t.twist));
    joystick_stamp_ = dds::to_domain(t.header.stamp);
  });
}

void AdmittanceNode::on_tracker_pose() {
  bool servo_input = false;
  tracker_poses_.take([&](const rigger_vision_TrackedPose& p, const dds_sample_info_t&) {
    const std::string id = dds::to_string(p.object_id);
    TrackerSample& sample = tracked_[id];
    // A refused or lost object's sample carries no pose: the servo's error stays that of the last pose
    // seen (the servo stops on its quality), not one against whatever the sample holds.
    if (p.tracked) sample.pose_world = dds::to_domain(p.pose.pose);
    sample.quality = p.quality;
    sample.tracked = p.tracked;
    sample.stamp = dds::to_domain(p.header.stamp);
    servo_input = servo_input || id == servo_object_ || id == servo_target_;
  });
  if (servo_input) servo_step();
}

void AdmittanceNode::on_crane_state() {
  crane_states_.take([this](const rigger_crane_CraneState& c, const dds_sample_info_t&) {
    crane_state_ = CraneSample{c.fault, c.link_ok, dds::to_string(c.fault_text), dds::EventLoop::Clock::now(),
                               Eigen::Vector3d(c.position_m[0], c.position_m[1], c.position_m[2])};
  });
  check_crane();
}

void AdmittanceNode::on_directory() {
  if (directory_.update()) check_commander();
}

void AdmittanceNode::servo_step() {
  if (reference_ != ReferenceSource::kVisualServo || !servo_) return;
  const WallTime now = std::chrono::system_clock::now();
  const auto tracked_pose = [&](const std::string& id) {
    TrackedPose out;
    const auto it = tracked_.find(id);
    if (it == tracked_.end()) {
      out.age = Seconds(std::numeric_limits<double>::infinity());
      return out;
    }
    out.pose_world = it->second.pose_world;
    out.quality = it->second.tracked ? it->second.quality : 0.0;  // a lost object carries no pose
    out.age = std::chrono::duration_cast<Seconds>(now - it->second.stamp);
    return out;
  };
  const TrackedPose object = tracked_pose(servo_object_);
  servo_output_ = servo_->update(object, tracked_pose(servo_target_));
  // The servo's twist is the object's (world); the robot commands its TCP: v + w x (p_tcp - p_object).
  Twist at_tcp;
  if (servo_output_->tracking() && tcp_position_base_) {
    const Eigen::Vector3d p_tcp_world = pose_world_base_ * *tcp_position_base_;
    at_tcp = shift_twist(servo_output_->twist_world, p_tcp_world - object.pose_world.translation());
  }
  // A stopped servo is a zero reference at once (not one that runs on until it is stale).
  servo_reference_base_ = rotate(pose_world_base_.linear().transpose(), at_tcp);
  servo_reference_stamp_ = now;
}

void AdmittanceNode::check_commander() {
  if (commander_.empty() || mode_ == AdmittanceMode::kOff) return;
  const auto& services = directory_.services();
  const auto it = services.find(commander_);
  const bool alive = it != services.end() && it->second.alive && it->second.status != service::ServiceStatus::kStopping;
  if (alive) {
    commander_seen_ = true;
    return;
  }
  if (commander_seen_) {
    go_off(kFaultCommanderLost, "commander '" + commander_ + "' lost (" +
                                    (it == services.end() ? std::string("gone")
                                     : !it->second.alive  ? std::string("not alive")
                                                          : std::string("stopping")) +
                                    " on rigger/system/service_state)");
  } else if (dds::EventLoop::Clock::now() - commander_since_ > commander_grace_) {
    go_off(kFaultCommanderLost, "commander '" + commander_ + "' not seen alive on rigger/system/service_state within " +
                                    std::to_string(commander_grace_.count()) + " s of its command");
  }
}

void AdmittanceNode::check_crane() {
  if (mode_ != AdmittanceMode::kRobotAndCrane) return;
  if (crane_state_ && !crane_state_->link_ok) {
    go_off(kFaultCraneFault,
           std::string(protocol::crane::kState.name) + ": link down (" + crane_state_->fault_text + ")");
  } else if (crane_state_ && crane_state_->fault) {
    go_off(kFaultCraneFault, std::string(protocol::crane::kState.name) + ": fault (" + crane_state_->fault_text + ")");
  } else {
    const auto now = dds::EventLoop::Clock::now();
    const auto since = crane_state_ ? std::max(crane_state_->received, mode_since_) : mode_since_;
    if (now - since > crane_state_timeout_)
      go_off(kFaultCraneFault,
             "no rigger/crane/state for more than " + std::to_string(crane_state_timeout_.count()) + " s");
  }
}

void AdmittanceNode::go_off(const std::string& code, const std::string& text) {
  ctx_.log->error("{}: {}; mode {} -> OFF, robot and crane ramp to zero", code, text, to_string(mode_));
  node_fault_ = code;
  node_fault_text_ = text;
  mode_ = AdmittanceMode::kOff;
  reference_ = ReferenceSource::kNone;
  servo_.reset();
  robot_.set_reference_source(ReferenceSource::kNone);
  robot_.set_mode(AdmittanceMode::kOff);
  crane_.set_enabled(false);
  publish_state();
}

std::string AdmittanceNode::accept_servo_request(const rigger_admittance_AdmittanceCommand& c) {
  const std::string object = dds::to_string(c.servo_object);
  const std::string target = dds::to_string(c.servo_target);
  if (object.empty() || target.empty()) return "VISUAL_SERVO needs servo_object and servo_target";
  if (object == target) return "servo_object and servo_target are the same object '" + object + "'";
  const auto& p = c.servo_goal_in_target.position;
  const auto& q = c.servo_goal_in_target.orientation;
  const Eigen::Vector4d quaternion(q.w, q.x, q.y, q.z);
  if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z))
    return "servo_goal_in_target.position is not finite";
  if (!quaternion.allFinite() || std::abs(quaternion.norm() - 1.0) > 1e-3)
    return "servo_goal_in_target.orientation is not a unit quaternion (norm " + std::to_string(quaternion.norm()) + ")";
  VisualServoConfig servo_config = config_.visual_servo;
  servo_config.pose_target_load_insertion = dds::to_domain(c.servo_goal_in_target);
  servo_config.pose_target_load_insertion.linear() =
      Eigen::Quaterniond(q.w, q.x, q.y, q.z).normalized().toRotationMatrix();
  servo_.emplace(servo_config);
  servo_object_ = object;
  servo_target_ = target;
  servo_output_.reset();
  servo_reference_stamp_.reset();
  return "";
}

void AdmittanceNode::on_command() {
  commands_.take([this](const rigger_admittance_AdmittanceCommand& c, const dds_sample_info_t&) {
    const std::string source = dds::to_string(c.source);
    AdmittanceMode mode;
    switch (c.mode) {
      case rigger_admittance_ADMITTANCE_OFF:
        mode = AdmittanceMode::kOff;
        break;
      case rigger_admittance_ADMITTANCE_ROBOT:
        mode = AdmittanceMode::kRobot;
        break;
      case rigger_admittance_ADMITTANCE_ROBOT_AND_CRANE:
        mode = AdmittanceMode::kRobotAndCrane;
        break;
      default:
        ctx_.log->warn("command refused seq={} source={}: unknown mode {}", c.seq, source, static_cast<int>(c.mode));
        return;
    }
    ReferenceSource reference;
    switch (c.reference) {
      case rigger_admittance_REFERENCE_NONE:
        reference = ReferenceSource::kNone;
        break;
      case rigger_admittance_REFERENCE_JOYSTICK:
        reference = ReferenceSource::kJoystick;
        break;
      case rigger_admittance_REFERENCE_VISUAL_SERVO:
        reference = ReferenceSource::kVisualServo;
        break;
      default:
        ctx_.log->warn("command refused seq={} source={}: unknown reference {}", c.seq, source,
                       static_cast<int>(c.reference));
        return;
    }
    // Gains: each sequence is empty (keep) or six values; all-or-nothing.
    const auto bad_length = [](std::size_t n) { return n != 0 && n != 6; };
    const auto axes_given = dds::elements(c.axes);
    if (bad_length(dds::elements(c.mass).size()) || bad_length(dds::elements(c.damping).size()) ||
        bad_length(dds::elements(c.stiffness).size()) || bad_length(axes_given.size())) {
      ctx_.log->warn("command refused seq={} source={}: mass, damping, stiffness and axes need 0 or 6 values", c.seq,
                     source);
      return;
    }
    // A command's gains are the configured ones but for the sequences it gives (the IDL's contract): one
    // skill's gains (CollaborativeMoveLoad's path stiffness) never carry over into the next skill's motion.
    AdmittanceGains gains = config_.robot.gains;
    if (auto v = gains_vector(c.mass)) gains.mass = *v;
    if (auto v = gains_vector(c.damping)) gains.damping = *v;
    if (auto v = gains_vector(c.stiffness)) gains.stiffness = *v;
    if (auto p = find_problem(gains)) {
      ctx_.log->warn("command refused seq={} source={}: gains{}: {}", c.seq, source, p->pointer, p->problem);
      return;
    }
    if (axes_given.size() == 6) {
      std::array<bool, 6> axes{};
      for (std::size_t i = 0; i < 6; ++i) axes[i] = axes_given[i];
      robot_.set_selected_axes(axes);
    }
    if (mode != AdmittanceMode::kOff && safe_stop_.active()) {
      ctx_.log->warn("command refused seq={} source={}: safe stop in force: {}", c.seq, source, safe_stop_.describe());
      return;
    }
    robot_.set_gains(gains);  // validated above; a change blends in over gain_transition_time_s
    last_command_seq_ = c.seq;
    node_fault_.clear();  // any accepted command acknowledges a latched node fault
    node_fault_text_.clear();
    if (reference == ReferenceSource::kVisualServo) {
      if (const std::string refusal = accept_servo_request(c); !refusal.empty()) {
        ctx_.log->warn("command refused seq={} source={}: {}", c.seq, source, refusal);
        go_off(kFaultServoRequestInvalid, "command seq " + std::to_string(c.seq) + ": " + refusal);
        return;
      }
    } else {
      servo_.reset();
      servo_output_.reset();
      servo_object_.clear();
      servo_target_.clear();
    }
    commander_ = source;
    commander_seen_ = false;
    commander_since_ = dds::EventLoop::Clock::now();
    mode_since_ = commander_since_;
    mode_ = mode;
    reference_ = reference;
    robot_.set_reference_source(reference);
    robot_.set_mode(mode);  // also acknowledges a latched fault
    crane_.set_enabled(mode == AdmittanceMode::kRobotAndCrane);
    if (reference == ReferenceSource::kVisualServo) {
      const Eigen::Isometry3d goal = servo_->config().pose_target_load_insertion;
      ctx_.log->info(
          "command seq={} source={} mode={} reference=VISUAL_SERVO object={} target={} goal_in_target=({}, {}, "
          "{}) m",
          c.seq, source, to_string(mode), servo_object_, servo_target_, goal.translation().x(), goal.translation().y(),
          goal.translation().z());
    } else {
      ctx_.log->info("command seq={} source={} mode={} reference={}", c.seq, source, to_string(mode),
                     to_string(reference));
    }
    if (!dds::elements(c.stiffness).empty())
      ctx_.log->info("command seq={} stiffness=({}, {}, {}) N/m, ({}, {}, {}) N m/rad", c.seq, gains.stiffness[0],
                     gains.stiffness[1], gains.stiffness[2], gains.stiffness[3], gains.stiffness[4],
                     gains.stiffness[5]);
    check_commander();
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
  if (reference_ == ReferenceSource::kVisualServo && servo_reference_stamp_) {
    reference.source = ReferenceSource::kVisualServo;
    reference.twist = servo_reference_base_;
    reference.frame = ControlFrame::kBase;
    reference.age = age_of(servo_reference_stamp_);
  }
  if (!orientation_base_sensor_) {
    // Without the sensor's orientation the wrench cannot be turned into the base frame: zero.
    robot_output_ = AdmittanceOutput{};
    robot_twist_base_ = Twist{};
    if (mode_ != AdmittanceMode::kOff) publish_twist(Vector6d::Zero());
  } else {
    robot_output_ =
        robot_.step(dt, WrenchSample{wrench_sensor_, age_of(wrench_stamp_)}, *orientation_base_sensor_, reference);
    Twist twist = robot_output_.twist;
    if (robot_output_.frame == ControlFrame::kTool)
      twist = rotate(orientation_base_sensor_->normalized().toRotationMatrix(), twist);
    robot_twist_base_ = twist;
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
  check_commander();
  check_crane();
  servo_step();  // at the crane rate too: a tracker that went silent shows as stale here
  CraneInput input;
  const Eigen::Matrix3d R_world_base = pose_world_base_.linear();
  input.force_on_robot_world_n = R_world_base * robot_output_.wrench_base.force_n;
  input.force_age = orientation_base_sensor_ ? age_of(wrench_stamp_) : Seconds(std::numeric_limits<double>::infinity());
  input.robot_velocity_world_mps = R_world_base * robot_twist_base_.linear_mps;
  input.rope_offset_world_m = rope_offset_world();
  crane_output_ = crane_.step(dt, input);
  if (crane_output_.status.state != CraneState::kDisabled) {
    publish_crane(crane_output_.velocity_world_mps);
  } else if (crane_published_) {
    publish_crane(Eigen::Vector3d::Zero());  // once, on reaching DISABLED
    crane_published_ = false;
  }
  publish_state();
}

std::optional<Eigen::Vector3d> AdmittanceNode::rope_offset_world() const {
  if (!pose_rope_attachment_ || !crane_state_) return std::nullopt;
  if (dds::EventLoop::Clock::now() - crane_state_->received > crane_state_timeout_) return std::nullopt;
  const auto it = tracked_.find(rope_object_);
  if (it == tracked_.end() || !it->second.tracked || !(it->second.quality > 0.0) ||
      age_of(it->second.stamp) > rope_offset_max_age_)
    return std::nullopt;
  const Eigen::Vector3d attachment = (it->second.pose_world * *pose_rope_attachment_).translation();
  Eigen::Vector3d offset = attachment - crane_state_->position_m;  // crane frame = world (see the header)
  offset.z() = 0.0;  // the law uses the horizontal part
  return offset;
}

void AdmittanceNode::publish_twist(const Vector6d& twist_base) {
  rigger_sensing_TwistCommand out{};
  out.header.stamp = dds::wire_now();
  out.header.frame_id = dds::wire_string(robot_id_);  // the driver's base frame
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
  if (!node_fault_.empty()) return node_fault_;
  if (mode_ == AdmittanceMode::kOff) return "";
  if (!orientation_base_sensor_) return kFaultNoRobotState;
  if (robot_output_.status.fault != AdmittanceFault::kNone) return std::string(to_string(robot_output_.status.fault));
  if (crane_output_.status.fault != CraneFault::kNone) return std::string(to_string(crane_output_.status.fault));
  if (servo_stopped()) return std::string(to_string(servo_output_->stop_reason));
  return "";
}

bool AdmittanceNode::servo_stopped() const {
  return reference_ == ReferenceSource::kVisualServo && servo_output_ && !servo_output_->tracking();
}

void AdmittanceNode::publish_state() {
  const std::string code = fault_code();
  if (code != last_fault_code_ && node_fault_.empty() && !servo_stopped()) {
    // The laws' faults (the node's own are logged where they are raised; a servo stop is only reported:
    // a flickering tracker would flood the log).
    if (!code.empty())
      ctx_.log->warn("fault {} in mode {}: output is zero", code, to_string(mode_));
    else if (!last_fault_code_.empty())
      ctx_.log->info("fault {} cleared", last_fault_code_);
  }
  last_fault_code_ = code;
  rigger_admittance_AdmittanceState out{};
  out.header.stamp = dds::wire_now();
  out.header.frame_id = dds::wire_string(robot_id_);
  out.mode = mode_ == AdmittanceMode::kOff     ? rigger_admittance_ADMITTANCE_OFF
             : mode_ == AdmittanceMode::kRobot ? rigger_admittance_ADMITTANCE_ROBOT
                                               : rigger_admittance_ADMITTANCE_ROBOT_AND_CRANE;
  out.reference = reference_ == ReferenceSource::kNone       ? rigger_admittance_REFERENCE_NONE
                  : reference_ == ReferenceSource::kJoystick ? rigger_admittance_REFERENCE_JOYSTICK
                                                             : rigger_admittance_REFERENCE_VISUAL_SERVO;
  out.fault = !code.empty();
  out.fault_code = dds::wire_string(code);
  std::string text;
  if (!node_fault_.empty())
    text = node_fault_text_;
  else if (code == kFaultNoRobotState)
    text = "no rigger/robot/state received yet";
  else if (servo_stopped())
    text = "visual servo stopped: its reference is zero, the robot stays compliant";
  else if (!code.empty())
    text = "output is zero";
  out.fault_text = dds::wire_string(text);
  out.filtered_wrench = dds::to_wire_wrench(robot_output_.wrench_applied.stacked());
  out.robot_twist = dds::to_wire_twist(robot_output_.twist.stacked());
  out.crane_velocity = dds::to_wire_vector(crane_output_.velocity_world_mps);
  out.last_command_seq = last_command_seq_;
  // Servo: converged only while the servo runs and tracks; the error is NaN while unknown.
  const bool servo_running = reference_ == ReferenceSource::kVisualServo && servo_output_.has_value();
  out.servo_converged = servo_running && servo_output_->converged;
  out.servo_error_m = servo_running && servo_output_->error_valid ? servo_output_->error.distance_m
                                                                  : std::numeric_limits<double>::quiet_NaN();
  out.servo_error_rad = servo_running && servo_output_->error_valid ? servo_output_->error.angle_rad
                                                                    : std::numeric_limits<double>::quiet_NaN();
  state_.write(out);
}

}  // namespace rigger::control
