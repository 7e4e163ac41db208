#include "sim_runner.hpp"

#include <pthread.h>
#include <sched.h>

#include <algorithm>
#include <cstring>

#include "rigger/crane_protocol/modbus_context.hpp"
#include "rigger/crane_protocol/register_map.hpp"
#include "rigger/base/text.hpp"
#include "rigger/cell_config/calibration_board.hpp"

namespace rigger::cell_sim {
namespace {

using SteadyClock = std::chrono::steady_clock;
using std::chrono::nanoseconds;

const char* control_name(ControlKind kind) {
  switch (kind) {
    case ControlKind::kEstop:
      return "estop";
    case ControlKind::kSetHoldingForce:
      return "set_holding_force";
    case ControlKind::kSetLoadForce:
      return "set_load_force";
    case ControlKind::kPlcLink:
      return "plc_link";
    case ControlKind::kReset:
      return "reset";
  }
  return "unknown";
}

const char* refusal_code(sim::CommandStatus status) {
  switch (status) {
    case sim::CommandStatus::RejectedNonFinite:
      return "INVALID";
    case sim::CommandStatus::RejectedOutOfRange:
      return "OUT_OF_RANGE";
    case sim::CommandStatus::RejectedUnreachable:
      return "UNREACHABLE";
    case sim::CommandStatus::RejectedHeld:
      return "HELD";
    case sim::CommandStatus::RejectedNotFree:
      return "NOT_FREE";
    case sim::CommandStatus::Accepted:
      break;
  }
  return "";
}

bool gripper_changed(const sim::GripperState& a, const sim::GripperState& b) {
  return a.energized != b.energized || a.holding != b.holding || a.in_contact != b.in_contact || a.phase != b.phase ||
         a.holding_force_n != b.holding_force_n || a.slip_count != b.slip_count;
}

/// True at most once per `period` (for logs from the real-time loop).
bool throttle(SteadyClock::time_point& last, std::chrono::seconds period) {
  const auto now = SteadyClock::now();
  if (now - last < period) return false;
  last = now;
  return true;
}

}  // namespace

SimRunner::SimRunner(CellSimConfig config, sim::CellGeometry geometry, SimOutputs& outputs, Logger log)
    : config_(std::move(config)),
      geometry_(std::move(geometry)),
      outputs_(outputs),
      log_(std::move(log)),
      physics_(std::make_unique<sim::CellPhysics>(geometry_, config_.physics)),
      axes_(*physics_),
      plc_(std::make_unique<plc::PlcEmulator>(config_.plc, axes_)),
      pacer_(config_.real_time_factor > 0.0 ? config_.real_time_factor : 1.0) {
  const nanoseconds dt = physics_->timestep();
  plc_every_ = std::max<std::uint64_t>(1, static_cast<std::uint64_t>(nanoseconds(config_.plc_scan_period) / dt));
  wrench_every_ = steps_per_period(config_.wrench_rate_hz, dt);
  robot_every_ = steps_per_period(config_.robot_state_rate_hz, dt);
  gripper_every_ = steps_per_period(config_.gripper_state_rate_hz, dt);
  truth_every_ = steps_per_period(config_.ground_truth_rate_hz, dt);
  status_every_ = steps_per_period(config_.status_rate_hz, dt);
  index_truth({});
}

void SimRunner::index_truth(std::vector<std::string> removed) {
  truth_.objects.clear();
  for (const std::string& id : physics_->object_bodies()) truth_.objects.push_back({id, Eigen::Isometry3d::Identity()});
  truth_.removed = std::move(removed);
}

SimRunner::~SimRunner() {
  stop();
}

void SimRunner::set_camera(CameraWorker* camera, double rate_hz) {
  camera_ = camera;
  camera_every_ = camera ? steps_per_period(rate_hz, physics_->timestep()) : 0;
}

void SimRunner::start() {
  if (thread_.joinable()) return;
  if (config_.plc_link_up) plc_->start_server();
  stop_ = false;
  thread_ = std::thread([this] { run(); });
}

void SimRunner::stop() {
  stop_ = true;
  if (thread_.joinable()) thread_.join();
  make_safe();
}

void SimRunner::submit(SimCommand command) {
  const std::lock_guard<std::mutex> lock(mailbox_mutex_);
  mailbox_.push_back(std::move(command));
}

void SimRunner::step_for_test(std::uint64_t steps) {
  for (std::uint64_t i = 0; i < steps; ++i) one_step(std::chrono::system_clock::now());
}

void SimRunner::make_safe() {
  physics_->stop_robot();
  twist_.reset();
  axes_.apply_velocity(Eigen::Vector3d::Zero());
  plc_->stop_server();
}

void SimRunner::run() {
  if (config_.realtime_priority > 0) {
    sched_param param{};
    param.sched_priority = config_.realtime_priority;
    const int rc = pthread_setschedparam(pthread_self(), SCHED_FIFO, &param);
    if (rc != 0) {
      log_->warn("physics thread keeps the normal scheduler: SCHED_FIFO priority={} refused: {}",
                 config_.realtime_priority, std::strerror(rc));
    }
  }
  const bool paced = config_.real_time_factor > 0.0;
  const nanoseconds dt = physics_->timestep();
  auto steady_now = SteadyClock::now();
  pacer_.start(steady_now, physics_->sim_time());
  rate_wall_anchor_ = steady_now;
  rate_sim_anchor_ = physics_->sim_time();
  log_->info("physics running real_time_factor={} timestep_ms={} plc_scan_ms={} plc_port={}",
             paced ? config_.real_time_factor : 0.0, std::chrono::duration<double, std::milli>(dt).count(),
             config_.plc_scan_period.count(), plc_->port());
  while (!stop_.load(std::memory_order_relaxed)) {
    if (paced) {
      // Sleep until the next step is due, then compute it: step k is published at about k ms.
      const auto due = pacer_.wall_time_for(physics_->sim_time() + dt);
      steady_now = SteadyClock::now();
      if (due > steady_now) {
        std::this_thread::sleep_until(due);
      } else if (steady_now - due > config_.max_lag) {
        // Far behind (machine overloaded, debugger, a reset): skip ahead rather than run a burst
        // of steps whose publications would all carry nearly the same stamp.
        ++overruns_;
        pacer_.start(steady_now, physics_->sim_time());
        if (throttle(last_lag_log_, std::chrono::seconds(5))) {
          log_->warn("physics behind real time lag_ms={} overruns={}: skipping ahead",
                     std::chrono::duration_cast<std::chrono::milliseconds>(steady_now - due).count(), overruns_);
        }
      }
    }
    one_step(std::chrono::system_clock::now());
  }
}

void SimRunner::one_step(WallTime now) {
  drain_mailbox(now);
  if (swap_done_) {
    // The step that swapped is timed whole (what the pacing sees), and reported once done.
    const std::shared_ptr<std::promise<ModelSwapResult>> done = std::move(swap_done_);
    swap_done_.reset();
    step_and_publish(now);
    done->set_value({"", SteadyClock::now() - swap_started_});
    return;
  }
  step_and_publish(now);
}

void SimRunner::step_and_publish(WallTime now) {
  if (twist_ && now >= twist_->expires) {
    // No fresh twist within its timeout: the arm stops.
    physics_->stop_robot();
    twist_.reset();
  }
  if (steps_ % plc_every_ == 0) plc_->step(physics_->timestep() * static_cast<std::int64_t>(plc_every_));
  physics_->step(physics_->timestep());
  ++steps_;
  publish_due(now);
}

void SimRunner::drain_mailbox(WallTime now) {
  std::vector<SimCommand> commands;
  {
    const std::lock_guard<std::mutex> lock(mailbox_mutex_);
    if (mailbox_.empty()) return;
    commands.swap(mailbox_);
  }
  for (const SimCommand& command : commands) {
    std::visit([&](const auto& c) { apply(c, now); }, command);
  }
}

void SimRunner::apply(const ObjectMovesCommand& command, WallTime now) {
  (void)now;
  if (!command.claim->take()) return;  // its sender gave up waiting and reported it refused
  // All or nothing: a revision half applied would leave the physics on no revision at all.
  for (const ObjectMove& move : command.moves) {
    const sim::CommandResult allowed = physics_->can_move_free_object(move.id, move.pose_world_object);
    if (!allowed.ok()) {
      command.done->set_value(allowed.message);
      return;
    }
  }
  for (const ObjectMove& move : command.moves) physics_->move_free_object(move.id, move.pose_world_object);
  command.done->set_value("");
}

std::string SimRunner::prepare_swap(const ModelSwapCommand& command) const {
  if (twist_) return "a twist command drives the robot: the model is built anew only while the arm holds still";
  if (motion_) return "motion " + motion_->motion_id + " runs: the model is built anew only while the arm holds still";
  const sim::CommandResult continued = command.physics->continue_from(*physics_);
  if (!continued.ok()) return continued.message;
  for (const ObjectMove& move : command.moves) {
    const sim::CommandResult moved = command.physics->move_free_object(move.id, move.pose_world_object);
    if (!moved.ok()) return moved.message;
  }
  return "";
}

void SimRunner::apply(const ModelSwapCommand& command, WallTime now) {
  (void)now;
  if (!command.claim->take()) return;  // its sender gave up waiting and reported it refused
  swap_started_ = SteadyClock::now();
  const std::string refusal = prepare_swap(command);
  if (!refusal.empty()) {
    command.done->set_value({refusal, SteadyClock::now() - swap_started_});
    return;
  }
  std::vector<std::string> removed;
  const std::vector<std::string> kept = command.physics->object_bodies();
  for (const ObjectTruth& object : truth_.objects) {
    if (std::find(kept.begin(), kept.end(), object.id) == kept.end()) removed.push_back(object.id);
  }
  physics_ = command.physics;
  axes_.attach(*physics_);
  geometry_ = command.geometry;
  index_truth(std::move(removed));
  // Queued before the first snapshot of the new model is offered: the camera renders it with its renderer.
  if (camera_ && command.camera_renderer) camera_->replace_renderer(command.camera_renderer);
  last_gripper_published_valid_ = false;
  swap_done_ = command.done;
}

void SimRunner::apply(const TwistCommand& command, WallTime now) {
  (void)now;
  if (estop_) {
    if (throttle(last_refusal_log_, std::chrono::seconds(2))) {
      log_->warn("twist ignored seq={}: emergency stop pressed", command.seq);
    }
    return;
  }
  if (motion_ && !motion_->stop)
    end_motion(MotionPhase::kAborted, "PREEMPTED",
               "preempted by a twist command" + (command.source.empty() ? std::string() : " from " + command.source) +
                   " (seq " + std::to_string(command.seq) + ")",
               now);
  const sim::CommandResult result = physics_->set_tool_twist(command.twist_base);
  if (!result.ok()) {
    if (throttle(last_refusal_log_, std::chrono::seconds(2))) {
      log_->warn("twist refused seq={} reason={}", command.seq, result.message);
    }
    return;
  }
  twist_ = command;
  last_robot_command_seq_ = command.seq;
}

void SimRunner::apply(const MotionCommand& command, WallTime now) {
  if (estop_) {
    outputs_.publish_motion_status(
        {command.motion_id, MotionPhase::kFailed, "EMERGENCY_STOP", "emergency stop pressed"}, now);
    return;
  }
  if (command.kind == MotionKind::kStop) {
    physics_->stop_robot();
    twist_.reset();
    if (motion_ && !motion_->stop) end_motion(MotionPhase::kAborted, "STOPPED", "stopped by " + command.motion_id, now);
    motion_.reset();
    outputs_.publish_motion_status({command.motion_id, MotionPhase::kAccepted, "", "stopping"}, now);
    motion_ = ActiveMotion{command.motion_id, 0, nanoseconds(0), true};
    return;
  }
  const sim::CommandResult result = command.kind == MotionKind::kJoint
                                        ? physics_->move_joints(command.joint_goal_rad, command.speed_fraction)
                                        : physics_->move_tool(command.goal_base_tool, command.speed_fraction);
  if (!result.ok()) {
    outputs_.publish_motion_status(
        {command.motion_id, MotionPhase::kFailed, refusal_code(result.status), result.message}, now);
    return;
  }
  if (motion_) end_motion(MotionPhase::kAborted, "PREEMPTED", "preempted by " + command.motion_id, now);
  twist_.reset();
  const nanoseconds deadline = command.timeout.count() > 0 ? physics_->sim_time() + command.timeout : nanoseconds(0);
  motion_ = ActiveMotion{command.motion_id, result.motion_id, deadline, false};
  outputs_.publish_motion_status({command.motion_id, MotionPhase::kAccepted, "", ""}, now);
  outputs_.publish_motion_status({command.motion_id, MotionPhase::kExecuting, "", ""}, now);
}

void SimRunner::apply(const GripperCommand& command, WallTime now) {
  (void)now;
  if (estop_) {
    log_->warn("gripper command ignored seq={} energize={}: emergency stop pressed", command.seq, command.energize);
    return;
  }
  physics_->set_gripper_energized(command.energize);
  last_gripper_command_seq_ = command.seq;
  last_gripper_published_valid_ = false;  // publish the new state at once
}

void SimRunner::apply(const SimControlCommand& command, WallTime now) {
  ControlResult result{command.seq, command.source, command.kind, true, ""};
  switch (command.kind) {
    case ControlKind::kEstop:
      set_estop(command.on, now);
      result.message =
          command.on ? "e-stop pressed" : "e-stop released (the crane PLC's fault stays latched until reset)";
      break;
    case ControlKind::kSetHoldingForce: {
      const double force = command.value < 0.0 ? geometry_.gripper.holding_force_n : command.value;
      const sim::CommandResult r = physics_->set_gripper_holding_force(force);
      result.accepted = r.ok();
      result.message = r.ok() ? "holding force " + number_text(force) + " N" : r.message;
      break;
    }
    case ControlKind::kSetLoadForce: {
      const sim::CommandResult r = physics_->set_load_external_force(command.vector);
      result.accepted = r.ok();
      if (r.ok()) load_external_force_n_ = command.vector;
      result.message = r.ok() ? "load force set" : r.message;
      break;
    }
    case ControlKind::kPlcLink:
      if (command.on) {
        try {
          plc_->start_server();
          result.message = "PLC link up on port " + std::to_string(plc_->port());
        } catch (const std::exception& e) {
          result.accepted = false;
          result.message = e.what();
        }
      } else {
        plc_->stop_server();
        result.message = "PLC link down: Modbus server closed";
      }
      break;
    case ControlKind::kReset:
      try {
        reset_physics(now);
        result.message = "simulation reset";
      } catch (const std::exception& e) {
        result.accepted = false;
        result.message = std::string("reset failed: ") + e.what();
      }
      break;
  }
  log_->info("sim control kind={} seq={} source={} accepted={} message=\"{}\"", control_name(command.kind), command.seq,
             command.source, result.accepted, result.message);
  outputs_.publish_control_result(result, now);
}

void SimRunner::set_estop(bool pressed, WallTime now) {
  plc_->set_emergency_stop(pressed);
  if (pressed) {
    physics_->stop_robot();
    twist_.reset();
    if (motion_) end_motion(MotionPhase::kAborted, "EMERGENCY_STOP", "emergency stop pressed", now);
  }
  estop_ = pressed;
}

void SimRunner::reset_physics(WallTime now) {
  auto fresh = std::make_unique<sim::CellPhysics>(geometry_, config_.physics);
  if (motion_) end_motion(MotionPhase::kAborted, "RESET", "simulation reset", now);
  twist_.reset();
  axes_.attach(*fresh);
  physics_ = std::move(fresh);
  load_external_force_n_.setZero();
  set_estop(false, now);
  if (config_.plc_link_up && plc_->port() == 0) plc_->start_server();
  // Simulated time starts again from zero: re-anchor the pacer and the rate measurement.
  const auto steady_now = SteadyClock::now();
  pacer_.start(steady_now, physics_->sim_time());
  rate_wall_anchor_ = steady_now;
  rate_sim_anchor_ = physics_->sim_time();
  last_gripper_published_valid_ = false;
}

void SimRunner::end_motion(MotionPhase phase, const std::string& code, const std::string& message, WallTime now) {
  if (!motion_) return;
  outputs_.publish_motion_status({motion_->motion_id, phase, code, message}, now);
  motion_.reset();
}

void SimRunner::track_motion(const sim::RobotState& robot, WallTime now) {
  if (!motion_) return;
  if (motion_->stop) {
    if (robot.mode != sim::RobotMode::Stopping) end_motion(MotionPhase::kSucceeded, "", "at rest", now);
    return;
  }
  if (robot.motion.id != motion_->physics_id) return;
  switch (robot.motion.status) {
    case sim::MotionStatus::Reached:
      end_motion(MotionPhase::kSucceeded, "", "goal reached", now);
      return;
    case sim::MotionStatus::Failed:
      end_motion(MotionPhase::kFailed, "MOTION_FAILED", robot.motion.message, now);
      return;
    case sim::MotionStatus::Stopped:
      end_motion(MotionPhase::kAborted, "STOPPED", robot.motion.message, now);
      return;
    case sim::MotionStatus::Idle:
    case sim::MotionStatus::Running:
      break;
  }
  if (motion_->deadline.count() > 0 && physics_->sim_time() > motion_->deadline) {
    physics_->stop_robot();
    end_motion(MotionPhase::kFailed, "TIMEOUT", "motion did not finish within its timeout", now);
  }
}

void SimRunner::publish_due(WallTime now) {
  if (steps_ % wrench_every_ == 0) {
    outputs_.publish_wrench(
        config_.wrench_source == WrenchSource::kRaw ? physics_->wrench_tool() : physics_->external_wrench_tool(), now);
  }
  constexpr std::uint64_t kMotionCheckEvery = 10;  // motion events within 10 ms of simulated time
  const bool robot_due = steps_ % robot_every_ == 0;
  if (robot_due || (motion_ && steps_ % kMotionCheckEvery == 0)) {
    const sim::RobotState robot = physics_->robot_state();
    track_motion(robot, now);
    if (robot_due) {
      outputs_.publish_robot_state({robot, estop_, estop_ ? "emergency_stop" : "", last_robot_command_seq_}, now);
    }
  }
  const sim::GripperState gripper = physics_->gripper_state();
  if (steps_ % gripper_every_ == 0 || !last_gripper_published_valid_ ||
      gripper_changed(gripper, last_gripper_published_)) {
    outputs_.publish_gripper_state({gripper, last_gripper_command_seq_}, now);
    last_gripper_published_ = gripper;
    last_gripper_published_valid_ = true;
  }
  if (steps_ % truth_every_ == 0) {
    for (ObjectTruth& object : truth_.objects) object.pose_world_object = *physics_->pose_world_object(object.id);
    outputs_.publish_ground_truth(truth_, now);
    truth_.removed.clear();
  }
  if (camera_ && steps_ % camera_every_ == 0) {
    // Every object (the rasteriser's boxes, the markers' faces: a renderer skips the ids it does not draw),
    // by its entity id, where the physics has it, and the positions of every body (what the MuJoCo renderer
    // draws): a copy of a few hundred numbers.
    CameraSnapshot snapshot;
    snapshot.stamp = now;
    for (const ObjectTruth& object : truth_.objects)
      snapshot.poses.push_back({object.id, *physics_->pose_world_object(object.id)});
    if (const auto& board = geometry_.robot.calibration_board) {
      snapshot.poses.push_back(
          {cell::calibration_board_id("robot"), physics_->robot_state().pose_world_tool * board->pose_tool_board});
    }
    physics_->copy_kinematic_state(snapshot.state);
    camera_->offer(std::move(snapshot));
  }
  if (steps_ % status_every_ == 0) {
    update_measured_rate(SteadyClock::now());
    outputs_.publish_status(status_report(), now);
  }
}

void SimRunner::update_measured_rate(SteadyClock::time_point wall_now) {
  const auto wall = wall_now - rate_wall_anchor_;
  if (wall < std::chrono::seconds(1)) return;
  const auto sim = physics_->sim_time() - rate_sim_anchor_;
  measured_rate_ = std::chrono::duration<double>(sim).count() / std::chrono::duration<double>(wall).count();
  rate_wall_anchor_ = wall_now;
  rate_sim_anchor_ = physics_->sim_time();
}

StatusReport SimRunner::status_report() const {
  StatusReport r;
  r.sim_time_s = std::chrono::duration<double>(physics_->sim_time()).count();
  r.steps = steps_;
  r.real_time_factor_target = config_.real_time_factor;
  r.real_time_factor_measured = measured_rate_;
  r.overruns = overruns_;
  r.mujoco_warnings = physics_->diagnostics().mujoco_warning_count;
  if (camera_) {
    r.camera_frames = camera_->frames();
    r.camera_frames_dropped = camera_->dropped();
  }
  r.estop_pressed = estop_;
  r.plc_port = plc_->port();
  r.plc_link_up = r.plc_port != 0;
  const plc::PlcSnapshot snapshot = plc_->snapshot();
  r.plc_clients = snapshot.server.clients;
  r.plc_status_word = crane::encode_status_word(snapshot.status.flags);
  r.plc_fault_code = static_cast<std::uint16_t>(snapshot.status.fault_code);
  r.plc_heartbeat = snapshot.status.plc_heartbeat;
  r.plc_control_word = snapshot.command_registers[crane::reg::kControlWord];
  r.gateway_heartbeat = snapshot.command_registers[crane::reg::kGatewayHeartbeat];
  if (snapshot.command) r.plc_setpoint_mps = snapshot.command->velocity_mps;
  r.plc_drive_command_mps = snapshot.velocity_command_mps;
  const sim::CraneState crane = physics_->crane_state();
  const plc::CraneAxesMeasurement axes = to_plc_axes(crane, geometry_.crane.rail_height_m);
  r.crane_position_m = axes.position_m;
  r.crane_velocity_mps = axes.velocity_mps;
  r.crane_load_kg = axes.load_kg;
  r.crane_sway_rad = crane.sway_angle_rad;
  r.gripper_holding_force_n = physics_->gripper_state().holding_force_n;
  r.load_external_force_n = load_external_force_n_;
  return r;
}

}  // namespace rigger::cell_sim
