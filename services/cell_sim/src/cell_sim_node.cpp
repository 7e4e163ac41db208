#include "cell_sim_node.hpp"

#include <cmath>
#include <fstream>
#include <vector>

#include "camera_renderers.hpp"
#include "rigger/cell_config/cell_diff.hpp"
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
  app.add_option("--cell", cell_file, "Cell file (overrides cell_file; \"\": the configuration's)");
}

CellSimNode::CellSimNode(service::ServiceContext& ctx, const CommandLine& command_line)
    : ctx_(ctx),
      config_(read_cell_sim_config(ctx.config, command_line.cell_file)),
      twist_gate_(config_.max_command_future, config_.max_twist_timeout),
      motion_status_(ctx.participant, protocol::robot::kMotionStatus),
      gripper_state_(ctx.participant, protocol::robot::kGripperState),
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
    ros2_camera_info_.emplace(ctx.participant, r.camera_info_dds_topic, ros2::qos::sensor_data());
    ros2_twist_.emplace(ctx.participant, r.twist_dds_topic, ros2::qos::reliable_default());
    ros2_joint_states_.emplace(ctx.participant, r.joint_states_dds_topic, ros2::qos::system_default());
    ctx.log->info(
        "robot and camera as ROS 2 drivers: wrench={} joint_states={} twist={} image={} camera_info={} base_frame={}",
        r.wrench_dds_topic, r.joint_states_dds_topic, r.twist_dds_topic, r.image_dds_topic, r.camera_info_dds_topic,
        r.base_frame);
  } else {
    wrench_.emplace(ctx.participant, protocol::robot::kWrench, written_by_physics(dds::qos::sensor_stream()));
    robot_state_.emplace(ctx.participant, protocol::robot::kState, written_by_physics(dds::qos::sensor_stream()));
    image_.emplace(ctx.participant, protocol::vision::kCameraImage);
    camera_info_.emplace(ctx.participant, protocol::vision::kCameraInfo);
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

  std::string camera_text = "off";
  if (config_.camera_enabled) {
    bool mujoco = false;
    try {
      const sim::CameraScene drawn = sim::load_camera_scene(config_.cell_file, config_.camera_id);
      pose_world_camera_true_ = drawn.pose_world_camera * config_.camera_pose_error;
      const sim::CameraScene scene = as_rendered(drawn);
      const CameraRendererKind renderer = resolve_renderer(config_.camera_renderer, geometry, scene.camera);
      camera_kind_ = renderer;
      mujoco = renderer == CameraRendererKind::kMujoco;
      if (mujoco && !ros2_image_) depth_.emplace(ctx.participant, protocol::vision::kCameraDepth);
      camera_ = std::make_unique<CameraWorker>(
          scene.camera, renderer_factory(renderer, config_, scene, mujoco ? runner_->copy_physics_model() : nullptr),
          [this](const CameraImages& images, WallTime stamp) { publish_images(images, stamp); },
          [this] { return camera_demand(); });
    } catch (const sim::CameraSceneError& e) {
      fail_config(ctx.config, "cell_file", e);
    } catch (const sim::GlUnavailableError& e) {
      // No silent black image: a camera that cannot render stops the start, and says how to go on.
      ctx.config.fail("camera", std::string("the mujoco renderer cannot start: ") + e.what() +
                                    " Without EGL, set camera/renderer to \"raster\" (the cell file's boxes only)");
    } catch (const std::invalid_argument& e) {
      ctx.config.fail("camera", e.what());
    }
    publish_camera_info(camera_->camera());
    camera_text = std::to_string(camera_->camera().width_px) + "x" + std::to_string(camera_->camera().height_px) +
                  (mujoco ? " mujoco" : " raster");
    if (!config_.camera_pose_error.isApprox(Eigen::Isometry3d::Identity())) {
      const Eigen::Isometry3d& e = config_.camera_pose_error;
      ctx.log->warn("camera is off its cell-file pose by {:.1f} mm and {:.2f} deg (camera/pose_error)",
                    1000.0 * e.translation().norm(),
                    Eigen::AngleAxisd(e.rotation()).angle() * 180.0 / 3.14159265358979323846);
    }
    runner_->set_camera(camera_.get(), config_.camera_rate_hz.value_or(camera_->camera().rate_hz));
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
  try {
    running_cell_ = cell::load_cell_file(config_.cell_file);
    std::ifstream in(config_.cell_file, std::ios::binary);
    running_doc_ = nlohmann::json::parse(in);  // valid and bounded: load_cell_file read it
  } catch (const std::exception& e) {
    fail_config(ctx.config, "cell_file", e);
  }
  follower_ = std::make_unique<cell_follower::CellFollower>(
      ctx.participant, ctx.loop, ctx.log, config_.cell_file,
      [this](const cell_follower::FollowedRevision& next) { return on_revision(next); }, &ctx.announcer);
  ctx.log->info("cell_sim started cell_file={} plc={}:{} real_time_factor={} camera={}", config_.cell_file.string(),
                config_.plc.server.address, runner_->plc_port(), config_.real_time_factor,
                camera_text);
}

sim::CameraScene CellSimNode::as_rendered(sim::CameraScene scene) const {
  scene = resize_camera(std::move(scene), config_.camera_width_px, config_.camera_height_px);
  // Rendered from where the camera really is: where the start's drawing put it, times camera/pose_error. A
  // revision that draws the camera elsewhere (a calibration) changes what the cell says, not where it is.
  scene.pose_world_camera = pose_world_camera_true_;
  return scene;
}

CellSimNode::~CellSimNode() {
  runner_->stop();
  ctx_.log->info("cell_sim stopped: arm stopped, crane stopped, Modbus server closed");
}

// The physics thread applies the moves at its next step (1 ms of simulated time): the loop waits for it, so
// the follower reports what the physics did, not what it was asked.
cell_follower::Outcome CellSimNode::on_revision(const cell_follower::FollowedRevision& next) {
  const RevisionPlan plan =
      plan_revision(cell::diff_cells(running_cell_, running_doc_, next.cell, next.document), running_cell_, next.cell);
  if (!plan.refusal.empty()) return cell_follower::Outcome::refuse(plan.refusal);
  for (const std::string& id : plan.cameras_redrawn) {
    if (!camera_ || id != config_.camera_id) continue;
    const Eigen::Isometry3d off = next.cell.pose_root_entity(id).inverse() * pose_world_camera_true_;
    ctx_.log->info("camera drawn anew by cell revision {} id={}: it stays where it is, {:.2f} mm and {:.3f} deg from "
                   "the new drawing",
                   next.revision, id, 1000.0 * off.translation().norm(),
                   Eigen::AngleAxisd(off.rotation()).angle() * 180.0 / 3.14159265358979323846);
  }
  if (plan.rebuild) return rebuild(next, plan);
  if (plan.moves.empty()) return take(next);
  ObjectMovesCommand command;
  command.moves = plan.moves;
  command.done = std::make_shared<std::promise<std::string>>();
  const std::shared_ptr<CommandClaim> claim = command.claim;
  std::future<std::string> done = command.done->get_future();
  runner_->submit(std::move(command));
  // Once the physics thread has taken the moves it finishes them within its step: wait for that.
  if (done.wait_for(std::chrono::seconds(2)) != std::future_status::ready && claim->withdraw())
    return cell_follower::Outcome::refuse("the physics thread did not apply the moves within 2 s");
  const std::string refusal = done.get();
  if (!refusal.empty()) return cell_follower::Outcome::refuse(refusal);
  for (const ObjectMove& move : plan.moves) {
    const Eigen::Vector3d p = move.pose_world_object.translation();
    ctx_.log->info("object moved by cell revision {} id={} position_m=[{:.4f}, {:.4f}, {:.4f}]", next.revision, move.id,
                   p.x(), p.y(), p.z());
  }
  return take(next);
}

// Building the model (STEP models read, MuJoCo compiling, the camera's model copied) takes a while: it happens
// here, on the event loop, while the physics runs on; the physics thread only swaps at its next step.
cell_follower::Outcome CellSimNode::rebuild(const cell_follower::FollowedRevision& next, const RevisionPlan& plan) {
  const auto build_start = SteadyClock::now();
  ModelSwapCommand command;
  std::string kept_out;  // objects the rasteriser does not draw
  const auto camera_made = std::make_shared<std::promise<std::string>>();
  std::future<std::string> camera_renderer = camera_made->get_future();
  try {
    command.geometry = sim::parse_cell_geometry(next.document.dump(), next.cell.source, next.model_dir);
    command.physics = std::make_shared<sim::CellPhysics>(command.geometry, config_.physics);
    if (camera_) {
      const sim::CameraScene scene = as_rendered(sim::camera_scene_from(next.cell, config_.camera_id));
      for (const sim::ObjectGeometry& object : command.geometry.objects) {
        if (!object.box_size_m) kept_out += (kept_out.empty() ? "" : ", ") + object.id;
      }
      // Made on the camera thread before its next frame; what became of it comes back here.
      command.camera_renderer =
          [make =
               renderer_factory(camera_kind_, config_, scene,
                                camera_kind_ == CameraRendererKind::kMujoco ? command.physics->copy_model() : nullptr),
           made = camera_made]() {
            try {
              std::unique_ptr<FrameRenderer> renderer = make();
              made->set_value("");
              return renderer;
            } catch (const std::exception& e) {
              made->set_value(e.what());
              throw;
            }
          };
    }
  } catch (const std::exception& e) {
    return cell_follower::Outcome::refuse(std::string("cell_sim cannot build the new cell's model: ") + e.what());
  }
  command.moves = plan.moves;
  command.done = std::make_shared<std::promise<ModelSwapResult>>();
  const std::shared_ptr<CommandClaim> claim = command.claim;
  std::future<ModelSwapResult> done = command.done->get_future();
  const auto build = SteadyClock::now() - build_start;
  runner_->submit(std::move(command));
  // Once the physics thread has taken the swap it finishes it within its step: wait for that.
  if (done.wait_for(std::chrono::seconds(2)) != std::future_status::ready && claim->withdraw())
    return cell_follower::Outcome::refuse("the physics thread did not swap the model within 2 s");
  const ModelSwapResult result = done.get();
  if (!result.refusal.empty()) return cell_follower::Outcome::refuse(result.refusal);
  const auto ms = [](auto d) { return std::chrono::duration<double, std::milli>(d).count(); };
  ctx_.log->info("cell model built anew by cell revision {}: {} build_ms={:.1f} swap_step_ms={:.2f}", next.revision,
                 plan.rebuild_reason, ms(build), ms(result.swap_step));
  if (camera_) {
    // The physics runs the new cell whatever the camera does; a camera left on the old model is said.
    const auto camera_start = SteadyClock::now();
    if (camera_renderer.wait_for(std::chrono::seconds(5)) != std::future_status::ready) {
      ctx_.log->warn("camera renderer for cell revision {} not made within 5 s: the camera shows the old model",
                     next.revision);
    } else if (const std::string error = camera_renderer.get(); !error.empty()) {
      ctx_.log->error("camera renderer for cell revision {} cannot be made: {}: the camera shows the old model",
                      next.revision, error);
    } else {
      ctx_.log->info("camera renders cell revision {} ready_after_ms={:.1f}", next.revision,
                     ms(SteadyClock::now() - camera_start));
    }
  }
  if (camera_kind_ == CameraRendererKind::kRaster && !kept_out.empty()) {
    ctx_.log->warn(
        "camera renderer stays raster (chosen at start): it does not draw {}, given by STEP models; "
        "set camera/renderer to \"mujoco\" to see them",
        kept_out);
  }
  return take(next);
}

cell_follower::Outcome CellSimNode::take(const cell_follower::FollowedRevision& next) {
  running_cell_ = next.cell;
  running_doc_ = next.document;
  return cell_follower::Outcome::take();
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

}  // namespace rigger::cell_sim
