#include "dds_devices.hpp"

#include "rigger/dds/conversions.hpp"
#include "rigger/protocol/robot.hpp"

namespace rigger::skill_sdk {

namespace {

RobotSnapshot to_snapshot(const rigger_robot_RobotState& s) {
  RobotSnapshot out;
  out.stamp = dds::to_domain(s.header.stamp);
  out.frame = dds::to_string(s.header.frame_id);
  out.tool_pose = dds::to_domain(s.tool_pose);
  out.moving = s.moving;
  out.fault = dds::to_string(s.fault);
  return out;
}

}  // namespace

DdsRobot::DdsRobot(const dds::Participant& participant, dds::EventLoop& loop, Logger log, std::string source)
    : DdsProxy(loop, std::move(log), std::move(source)),
      commands_(participant, protocol::robot::kCmdMotion),
      status_(participant, protocol::robot::kMotionStatus),
      state_(participant, loop, protocol::robot::kState, to_snapshot),
      pending_(loop) {
  loop_.on_data(status_, [this] { on_status(); });
}

OpId DdsRobot::move(const MotionGoal& goal, std::chrono::nanoseconds timeout, OpCallback done) {
  return send(goal.kind == MotionGoal::Kind::kJoint ? rigger_robot_MOTION_JOINT : rigger_robot_MOTION_CARTESIAN, &goal,
              timeout, std::move(done));
}

OpId DdsRobot::stop(std::chrono::nanoseconds timeout, OpCallback done) {
  return send(rigger_robot_MOTION_STOP, nullptr, timeout, std::move(done));
}

OpId DdsRobot::send(rigger_robot_MotionKind kind, const MotionGoal* goal, std::chrono::nanoseconds timeout,
                    OpCallback done) {
  const OpId id = next_op();
  const std::uint64_t seq = next_seq();
  const std::string motion_id = source_ + "-" + std::to_string(seq);
  rigger_robot_MotionCommand c{};
  const std::string frame = goal ? goal->frame : std::string();
  std::vector<double> joints = goal ? goal->joint_goal_rad : std::vector<double>{};
  c.header.stamp = dds::wire_now();
  c.header.frame_id = dds::wire_string(frame);
  c.motion_id = dds::wire_string(motion_id);
  c.seq = seq;
  c.kind = kind;
  dds::wire_sequence(c.joint_goal, joints);
  c.pose_goal = dds::to_wire(goal ? goal->pose_frame_tool : Eigen::Isometry3d::Identity());
  c.speed_scale = goal ? goal->speed_scale : 1.0;
  c.timeout_s = to_seconds(timeout);
  c.source = dds::wire_string(source_);
  pending_.start(id, Pending{motion_id, kind != rigger_robot_MOTION_STOP}, std::move(done), timeout, [this](OpId op) {
    const Pending p = *pending_.find(op);
    pending_.finish(op, OpResult::failure("TIMEOUT", "motion " + p.motion_id + " did not end within its timeout"));
    // A motion that overran is stopped; nobody waits for that stop (the caller gets TIMEOUT).
    if (p.stop_on_timeout) stop(std::chrono::seconds(5), [](const OpResult&) {});
  });
  const dds_return_t rc = commands_.write(c);
  if (rc != DDS_RETCODE_OK) {
    // Reported from the loop, not from inside the caller's call, so callbacks never re-enter.
    loop_.post([this, id, rc] {
      pending_.finish(
          id, OpResult::failure("MOTION_FAILED", "cmd_motion write failed: " + std::string(dds_strretcode(rc))));
    });
  }
  log_->debug("motion sent id={} kind={}", motion_id, static_cast<int>(kind));
  return id;
}

void DdsRobot::on_status() {
  std::vector<std::pair<OpId, OpResult>> results;
  status_.take([&](const rigger_robot_MotionStatus& s, const dds_sample_info_t&) {
    const std::string motion_id = dds::to_string(s.motion_id);
    for (OpId id : pending_.ids()) {
      if (pending_.find(id)->motion_id != motion_id) continue;
      const std::string code = dds::to_string(s.code), message = dds::to_string(s.message);
      switch (s.state) {
        case rigger_robot_MOTION_SUCCEEDED:
          results.emplace_back(id, OpResult::success(message));
          break;
        case rigger_robot_MOTION_FAILED:
          results.emplace_back(id, OpResult::failure("MOTION_FAILED", (code.empty() ? "" : code + ": ") + message));
          break;
        case rigger_robot_MOTION_ABORTED:
          results.emplace_back(id, OpResult::failure("MOTION_ABORTED", (code.empty() ? "" : code + ": ") + message));
          break;
        default:
          break;  // ACCEPTED, EXECUTING: progress only
      }
    }
  });
  for (const auto& [id, result] : results) pending_.finish(id, result);
}

OpId DdsRobot::next_state(std::chrono::nanoseconds timeout, std::function<void(std::optional<RobotSnapshot>)> done) {
  const OpId id = next_op();
  const WallTime since = std::chrono::system_clock::now();
  const OpId wait_id = state_.wait([since](const RobotSnapshot& s) { return s.stamp >= since; }, timeout,
                                   [this, id, done = std::move(done)](std::optional<RobotSnapshot> s) {
                                     state_waits_.erase(id);
                                     done(std::move(s));
                                   });
  state_waits_[id] = wait_id;
  return id;
}

void DdsRobot::cancel(OpId id) {
  auto w = state_waits_.find(id);
  if (w != state_waits_.end()) {
    state_.cancel(w->second);
    state_waits_.erase(w);
    return;
  }
  pending_.cancel(id);
}

DdsGripper::DdsGripper(const dds::Participant& participant, dds::EventLoop& loop, Logger log, std::string source)
    : DdsProxy(loop, std::move(log), std::move(source)),
      commands_(participant, protocol::robot::kGripperCmd),
      state_(participant, loop, protocol::robot::kGripperState,
             [](const rigger_robot_GripperState& s) {
               GripperSnapshot g;
               g.stamp = dds::to_domain(s.header.stamp);
               g.energized = s.energized;
               g.contact = s.contact;
               g.holding = s.holding;
               g.holding_force_n = s.holding_force_n;
               g.last_command_seq = s.last_command_seq;
               return g;
             }) {}

OpId DdsGripper::set_energized(bool energize, std::chrono::nanoseconds timeout, OpCallback done) {
  const std::uint64_t seq = next_seq();
  rigger_robot_GripperCommand c{};
  c.header.stamp = dds::wire_now();
  c.seq = seq;
  c.energize = energize;
  c.source = dds::wire_string(source_);
  const OpId id = state_.wait(
      [seq, energize](const GripperSnapshot& s) { return s.last_command_seq >= seq && s.energized == energize; },
      timeout, [done = std::move(done), energize](std::optional<GripperSnapshot> s) {
        if (s) done(OpResult::success(energize ? "energized" : "released"));
        else done(OpResult::failure("TIMEOUT", std::string("the gripper did not confirm ") + (energize ? "energize" : "release")));
      });
  write_command(commands_, c, "gripper command");
  return id;
}

OpId DdsGripper::wait_state(std::function<bool(const GripperSnapshot&)> predicate, std::chrono::nanoseconds timeout,
                            StateCallback done) {
  return state_.wait(std::move(predicate), timeout, std::move(done));
}

}  // namespace rigger::skill_sdk
