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

using SteadyClock = std::chrono::steady_clock;

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

std::optional<ControlKind> to_domain(rigger_sim_SimControlKind kind) {
  switch (kind) {
    case rigger_sim_SIM_ESTOP:
      return ControlKind::kEstop;
    case rigger_sim_SIM_SET_HOLDING_FORCE:
      return ControlKind::kSetHoldingForce;
    case rigger_sim_SIM_SET_LOAD_FORCE:
      return ControlKind::kSetLoadForce;
    case rigger_sim_SIM_PLC_LINK:
      return ControlKind::kPlcLink;
    case rigger_sim_SIM_RESET:
      return ControlKind::kReset;
  }
  return std::nullopt;
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

// The physics thread writes these every step or every few: with a liveliness lease per writer,
// asserted by each write, readers see a hung physics thread within the lease, not only a dead process.
dds::Qos written_by_physics(dds::Qos qos) {
  dds_qset_liveliness(qos.get(), DDS_LIVELINESS_MANUAL_BY_TOPIC, DDS_MSECS(dds::kStateStreamLease.count()));
  return qos;
}

// Errors in files the configuration points at are configuration errors: exit code 2, naming the key.
[[noreturn]] void fail_config(const Config& config, const std::string& key, const std::exception& e) {
  config.fail(config.has(key) ? key : "", e.what());
}

}  // namespace

void CommandLine::add_to(CLI::App& app) {
  app.add_option("--plc-port", plc_port, "Modbus TCP port of the PLC emulator (overrides plc/port; 0: ephemeral)");
  app.add_option("--real-time-factor", real_time_factor,
                 "Simulated seconds per wall second (overrides real_time_factor; 0: as fast as possible)")
      ->check(CLI::Range(0.0, 1000.0));
}

CellSimNode::CellSimNode(service::ServiceContext& ctx, const CommandLine& command_line)
    : ctx_(ctx),
      config_(read_cell_sim_config(ctx.config)),
      twist_gate_(config_.max_command_future, config_.max_twist_timeout),
      motion_status_(ctx.participant, protocol::robot::kMotionStatus),
      gripper_state_(ctx.participant, protocol::robot::kGripperState),
      camera_info_(ctx.participant, protocol::vision::kCameraInfo),
      ground_truth_(ctx.participant, protocol::sim::kGroundTruth),
      sim_event_(ctx.participant, protocol::sim::kEvent),
      sim_status_(ctx.participant, protocol::sim::kStatus),
      motion_(ctx.participant, protocol::robot::kCmdMotion),
      gripper_(ctx.participant, protocol::robot::kGripperCmd),
      sim_control_(ctx.participant, protocol::sim::kControl) {
  if (command_line.plc_port) config_.plc.server.port = *command_line.plc_port;
  if (command_line.real_time_factor) {
    config_.real_time_factor = *command_line.real_time_factor;
    if (config_.real_time_factor > 0.0 && config_.real_time_factor < 0.05) {
      throw ConfigError("--real-time-factor", "", "expected 0 (unpaced) or a value in [0.05, 1000]");
    }
  }
  ctx.config.finish();
  if (config_.ros2_driver) {
    const CellSimConfig::Ros2Driver& r = *config_.ros2_driver;
    ros2_wrench_.emplace(ctx.participant, r.wrench_dds_topic, written_by_physics(ros2::qos::sensor_data()));
    ros2_image_.emplace(ctx.participant, r.image_dds_topic, ros2::qos::sensor_data());
    ros2_twist_.emplace(ctx.participant, r.twist_dds_topic, ros2::qos::reliable_default());
    ros2_joint_states_.emplace(ctx.participant, r.joint_states_dds_topic, ros2::qos::system_default());
    ctx.log->info("robot and camera as ROS 2 drivers: wrench={} joint_states={} twist={} image={} base_frame={}",
                  r.wrench_dds_topic, r.joint_states_dds_topic, r.twist_dds_topic, r.image_dds_topic, r.base_frame);
  } else {
    wrench_.emplace(ctx.participant, protocol::robot::kWrench, written_by_physics(dds::qos::sensor_stream()));
    robot_state_.emplace(ctx.participant, protocol::robot::kState, written_by_physics(dds::qos::sensor_stream()));
    image_.emplace(ctx.participant, protocol::vision::kCameraImage);
    twist_.emplace(ctx.participant, protocol::robot::kCmdTwist);
  }

  sim::CellGeometry geometry;
  try {
    geometry = sim::load_cell_geometry(config_.cell_file);
  } catch (const sim::CellGeometryError& e) {
    fail_config(ctx.config, "cell_file", e);
  }
  pose_world_base_ = geometry.robot.pose_world_base;
  try {
    runner_ = std::make_unique<SimRunner>(config_, geometry, static_cast<SimOutputs&>(*this), ctx.log);
  } catch (const sim::PhysicsModelError& e) {
    fail_config(ctx.config, "model_file", e);
  } catch (const sim::CellGeometryError& e) {
    fail_config(ctx.config, "cell_file", e);
  }

  if (config_.camera_enabled) {
    std::optional<sim::CameraScene> scene;
    try {
      scene = resize_camera(sim::load_camera_scene(config_.cell_file, config_.camera_id), config_.camera_width_px,
                            config_.camera_height_px);
    } catch (const sim::CameraSceneError& e) {
      fail_config(ctx.config, "cell_file", e);
    } catch (const std::invalid_argument& e) {
      ctx.config.fail("camera", e.what());
    }
    RendererFactory make_renderer;
    if (config_.camera_renderer == CameraRendererKind::kRaster) {
      sim::RenderSettings settings;
      settings.noise_stddev = config_.camera_noise_stddev;
      settings.blur_sigma_px = config_.camera_blur_sigma_px;
      settings.albedo = {{"load", 0.62}, {"target", 0.38}};  // the two boxes apart in grey
      make_renderer = [scene = *scene, settings] { return make_raster_renderer(scene, settings); };
    } else {
      sim::MujocoCameraSettings settings;
      settings.noise_stddev = config_.camera_noise_stddev;
      make_renderer = [scene = *scene, settings, model = runner_->copy_physics_model()] {
        return make_mujoco_renderer(model, scene, settings);
      };
      if (!ros2_image_) depth_.emplace(ctx.participant, protocol::vision::kCameraDepth);
    }
    try {
      camera_ = std::make_unique<CameraWorker>(
          scene->camera, make_renderer, [this](const CameraImages& images, WallTime stamp) { publish_images(images, stamp); });
    } catch (const sim::GlUnavailableError& e) {
      // No silent black image: a camera that cannot render stops the start, and says how to go on.
      ctx.config.fail("camera", std::string("the mujoco renderer cannot start (") + e.what() +
                                    "); install Mesa's EGL (libegl1, libgl1-mesa-dri) or set camera/renderer to \"raster\"");
    } catch (const std::invalid_argument& e) {
      ctx.config.fail("camera", e.what());
    }
    publish_camera_info(camera_->camera());
    runner_->set_camera(camera_.get(), config_.camera_rate_hz.value_or(scene->camera.rate_hz));
  }

  if (twist_) ctx.loop.on_data(*twist_, [this] { on_twist(); });
  if (ros2_twist_) ctx.loop.on_data(*ros2_twist_, [this] { on_ros2_twist(); });
  ctx.loop.on_data(motion_, [this] { on_motion(); });
  ctx.loop.on_data(gripper_, [this] { on_gripper(); });
  ctx.loop.on_data(sim_control_, [this] { on_sim_control(); });
  safe_stop_ = std::make_unique<safety::SafeStopListener>(
      ctx.participant, ctx.loop, std::vector<std::string>{"robot", "gripper"},
      [this](const std::string& resource, const safety::StopState& s) {
        if (!s.active) {
          ctx_.log->warn("safe stop reset {} by={} reason=\"{}\"", resource, s.source, s.reason);
          return;
        }
        ctx_.log->error("SAFE_STOP {} by={} reason=\"{}\"", resource, s.source, s.reason);
        if (resource != "robot") return;
        // Zero twist and a stop of any point-to-point motion, at once; the gate forgets the stream so
        // nothing sent before the stop applies after its reset.
        twist_gate_.reset();
        TwistCommand zero;
        zero.source = "safe stop";
        zero.expires = std::chrono::system_clock::now() + std::chrono::milliseconds(100);
        runner_->submit(zero);
        MotionCommand stop;
        stop.motion_id = "safe-stop";
        stop.kind = MotionKind::kStop;
        runner_->submit(stop);
      });
  runner_->start();
  ctx.log->info("cell_sim started cell_file={} plc={}:{} real_time_factor={} camera={}", config_.cell_file.string(),
                config_.plc.server.address, runner_->plc_port(), config_.real_time_factor,
                camera_ ? std::to_string(camera_->camera().width_px) + "x" + std::to_string(camera_->camera().height_px)
                        : std::string("off"));
}

CellSimNode::~CellSimNode() {
  runner_->stop();
  ctx_.log->info("cell_sim stopped: arm stopped, crane stopped, Modbus server closed");
}

bool CellSimNode::log_allowed(SteadyClock::time_point& last) {
  const auto now = SteadyClock::now();
  if (now - last < std::chrono::seconds(2)) return false;
  last = now;
  return true;
}

// ---- commands -------------------------------------------------------------------------------

void CellSimNode::on_twist() {
  twist_->take([this](const rigger_sensing_TwistCommand& c, const dds_sample_info_t&) { take_twist(c); });
}

// MoveIt Servo's input as the simulated driver reads it: a TwistStamped in the base frame drives for
// twist_timeout (it carries no sequence number or timeout of its own).
void CellSimNode::on_ros2_twist() {
  const CellSimConfig::Ros2Driver& r = *config_.ros2_driver;
  ros2_twist_->take([&](const geometry_msgs_msg_dds__TwistStamped_& in, const dds_sample_info_t&) {
    rigger_sensing_TwistCommand c{};
    c.header = ros2::to_rigger(in.header_);
    if (dds::to_string(c.header.frame_id) == r.base_frame) c.header.frame_id = const_cast<char*>(kBaseFrame);
    c.seq = ++ros2_twist_seq_;
    c.twist = ros2::to_rigger(in.twist_);
    c.timeout_s = to_seconds(r.twist_timeout);
    c.source = const_cast<char*>("ros2");
    take_twist(c);
  });
}

void CellSimNode::take_twist(const rigger_sensing_TwistCommand& c) {
  const WallTime now = std::chrono::system_clock::now();
  const std::string frame = dds::to_string(c.header.frame_id);
  const dds::Vector6d twist = dds::to_domain(c.twist);
  std::string refusal;
  if (!frame.empty() && frame != kBaseFrame) {
    refusal = "frame '" + frame + "' is not the base frame '" + kBaseFrame + "'";
  } else if (!twist.allFinite()) {
    refusal = "twist not finite";
  } else if (safe_stop_->active()) {
    refusal = "safe stop in force: " + safe_stop_->describe();
  } else {
    const GateVerdict verdict = twist_gate_.offer(dds::to_domain(c.header.stamp), c.seq, c.timeout_s, now);
    if (verdict == GateVerdict::kAccepted) {
      TwistCommand command;
      command.twist_base.linear_mps = twist.head<3>();
      command.twist_base.angular_rad_per_s = twist.tail<3>();
      command.expires = *twist_gate_.expiry();
      command.seq = c.seq;
      command.source = dds::to_string(c.source);
      runner_->submit(command);
      return;
    }
    refusal = std::string(verdict_name(verdict));
  }
  ++twists_refused_;
  if (log_allowed(last_twist_log_)) {
    ctx_.log->warn("twist command ignored seq={} source={} reason={} refused_total={}", c.seq,
                   dds::to_string(c.source), refusal, twists_refused_);
  }
}

void CellSimNode::refuse_motion(const std::string& motion_id, const std::string& code, const std::string& message) {
  if (log_allowed(last_motion_log_)) {
    ctx_.log->warn("motion command refused motion_id={} code={} reason={}", motion_id, code, message);
  }
  publish_motion_status({motion_id, MotionPhase::kFailed, code, message}, std::chrono::system_clock::now());
}

void CellSimNode::on_motion() {
  motion_.take([this](const rigger_robot_MotionCommand& c, const dds_sample_info_t&) {
    const WallTime now = std::chrono::system_clock::now();
    MotionCommand command;
    command.motion_id = dds::to_string(c.motion_id);
    if (command.motion_id.empty()) {
      refuse_motion(command.motion_id, "INVALID", "motion_id is empty");
      return;
    }
    if (safe_stop_->active() && c.kind != rigger_robot_MOTION_STOP) {
      refuse_motion(command.motion_id, "SAFE_STOP", "safe stop in force: " + safe_stop_->describe());
      return;
    }
    const auto age = now - dds::to_domain(c.header.stamp);
    if (age > config_.max_motion_command_age || -age > config_.max_command_future) {
      refuse_motion(command.motion_id, "STALE",
                    "stamped " + std::to_string(std::chrono::duration<double>(age).count()) +
                        " s ago; accepted within " + std::to_string(config_.max_motion_command_age.count()) + " ms");
      return;
    }
    if (!(c.speed_scale > 0.0 && c.speed_scale <= 1.0)) {
      refuse_motion(command.motion_id, "INVALID",
                    "speed_scale must be in (0, 1], got " + std::to_string(c.speed_scale));
      return;
    }
    if (!std::isfinite(c.timeout_s) || c.timeout_s < 0.0) {
      refuse_motion(command.motion_id, "INVALID", "timeout_s must be >= 0 (0: none)");
      return;
    }
    command.speed_fraction = c.speed_scale;
    command.timeout = from_seconds(std::min(c.timeout_s, 3600.0));
    switch (c.kind) {
      case rigger_robot_MOTION_STOP:
        command.kind = MotionKind::kStop;
        break;
      case rigger_robot_MOTION_JOINT: {
        const auto goal = dds::elements(c.joint_goal);
        if (goal.size() != static_cast<std::size_t>(sim::kArmJointCount)) {
          refuse_motion(command.motion_id, "INVALID",
                        "joint_goal needs " + std::to_string(sim::kArmJointCount) + " values, got " +
                            std::to_string(goal.size()));
          return;
        }
        command.kind = MotionKind::kJoint;
        for (int i = 0; i < sim::kArmJointCount; ++i) command.joint_goal_rad[i] = goal[i];
        break;
      }
      case rigger_robot_MOTION_CARTESIAN: {
        const std::string frame = dds::to_string(c.header.frame_id);
        const Eigen::Isometry3d pose = dds::to_domain(c.pose_goal);
        if (frame.empty() || frame == kBaseFrame) {
          command.goal_base_tool = pose;
        } else if (frame == kWorldFrame) {
          command.goal_base_tool = pose_world_base_.inverse() * pose;
        } else {
          refuse_motion(command.motion_id, "UNKNOWN_FRAME",
                        "pose_goal frame '" + frame + "': expected '" + kBaseFrame + "' or '" + kWorldFrame + "'");
          return;
        }
        command.kind = MotionKind::kCartesian;
        break;
      }
      default:
        refuse_motion(command.motion_id, "INVALID", "unknown motion kind " + std::to_string(static_cast<int>(c.kind)));
        return;
    }
    runner_->submit(command);
  });
}

void CellSimNode::on_gripper() {
  gripper_.take([this](const rigger_robot_GripperCommand& c, const dds_sample_info_t&) {
    if (safe_stop_->active()) {
      ctx_.log->warn("gripper command refused energize={} seq={} source={}: safe stop in force: {}", c.energize, c.seq,
                     dds::to_string(c.source), safe_stop_->describe());
      return;
    }
    ctx_.log->info("gripper command energize={} seq={} source={}", c.energize, c.seq, dds::to_string(c.source));
    runner_->submit(GripperCommand{c.energize, c.seq});
  });
}

void CellSimNode::on_sim_control() {
  sim_control_.take([this](const rigger_sim_SimControl& c, const dds_sample_info_t&) {
    const std::optional<ControlKind> kind = to_domain(c.kind);
    SimControlCommand command;
    command.seq = c.seq;
    command.source = dds::to_string(c.source);
    command.on = c.on;
    command.value = c.value;
    command.vector = dds::to_domain(c.vector);
    std::string refusal;
    if (!kind) {
      refusal = "unknown control kind " + std::to_string(static_cast<int>(c.kind));
    } else if (!std::isfinite(c.value) || !command.vector.allFinite()) {
      refusal = "value or vector not finite";
    }
    if (!refusal.empty()) {
      ctx_.log->warn("sim control refused seq={} reason={}", c.seq, refusal);
      publish_control_result({c.seq, command.source, kind.value_or(ControlKind::kReset), false, refusal},
                             std::chrono::system_clock::now());
      return;
    }
    command.kind = *kind;
    runner_->submit(command);
  });
}

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
  for (const GroundTruth::Object& object : truth.objects) publish(object.id.c_str(), object.pose_world_object);
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

void CellSimNode::publish_images(const CameraImages& images, WallTime stamp) {
  const cv::Mat& image_mono8 = images.image_mono8;
  if (!image_mono8.isContinuous() || image_mono8.type() != CV_8UC1) return;  // the renderers' output is both
  // Depth first: a reader that has the image of a frame finds its depth already published.
  if (depth_ && images.depth_m.isContinuous() && images.depth_m.type() == CV_32FC1) {
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
}

void CellSimNode::publish_camera_info(const sim::CameraModel& camera) {
  // plumb_bob carries five coefficients; a cell file may give four (k3 = 0) or none.
  std::vector<double> d = camera.distortion;
  d.resize(5, 0.0);
  rigger_vision_CameraInfo w{};
  w.header.stamp = dds::wire_now();
  w.header.frame_id = const_cast<char*>(config_.camera_id.c_str());
  w.height = static_cast<std::uint32_t>(camera.height_px);
  w.width = static_cast<std::uint32_t>(camera.width_px);
  w.distortion_model = const_cast<char*>("plumb_bob");
  dds::wire_sequence(w.d, d);
  const double k[9] = {camera.fx_px, 0, camera.cx_px, 0, camera.fy_px, camera.cy_px, 0, 0, 1};
  const double r[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1};
  const double p[12] = {camera.fx_px, 0, camera.cx_px, 0, 0, camera.fy_px, camera.cy_px, 0, 0, 0, 1, 0};
  std::copy(std::begin(k), std::end(k), std::begin(w.k));
  std::copy(std::begin(r), std::end(r), std::begin(w.r));
  std::copy(std::begin(p), std::end(p), std::begin(w.p));
  camera_info_.write(w);
}

}  // namespace rigger::cell_sim
