#pragma once
/// @file
/// The DDS implementations of the device primitives (primitives.hpp):
///  - DdsRobot: rigger/robot/cmd_motion (commands QoS) with one motion_id per operation, completion from
///    rigger/robot/motion_status (events QoS, matched by motion_id), state from rigger/robot/state
///    (sensor stream QoS);
///  - DdsGripper: rigger/gripper/cmd (commands QoS, seq per command), confirmed by rigger/gripper/state
///    (state QoS) once it reports last_command_seq ≥ the command's seq with the requested energized flag.
/// Thread safety: the event loop thread.

#include <map>
#include <memory>
#include <string>

#include "dds_proxy.hpp"
#include "rigger/base/logging.hpp"
#include "rigger/dds/event_loop.hpp"
#include "rigger/dds/pubsub.hpp"
#include "rigger/skill_sdk/primitives.hpp"
#include "topic_condition.hpp"

namespace rigger::skill_sdk {

class DdsRobot final : public RobotMotion, private DdsProxy {
 public:
  /// `source` names the commands' sender (the executor id) and prefixes motion ids.
  DdsRobot(const dds::Participant& participant, dds::EventLoop& loop, Logger log, std::string source);

  OpId move(const MotionGoal& goal, std::chrono::nanoseconds timeout, OpCallback done) override;
  OpId stop(std::chrono::nanoseconds timeout, OpCallback done) override;
  OpId next_state(std::chrono::nanoseconds timeout, std::function<void(std::optional<RobotSnapshot>)> done) override;
  void cancel(OpId id) override;

 private:
  struct Pending {
    std::string motion_id;
    bool stop_on_timeout = false;
  };
  OpId send(rigger_robot_MotionKind kind, const MotionGoal* goal, std::chrono::nanoseconds timeout, OpCallback done);
  void on_status();

  dds::Writer<rigger_robot_MotionCommand> commands_;
  dds::Reader<rigger_robot_MotionStatus> status_;
  TopicCondition<rigger_robot_RobotState, RobotSnapshot> state_;
  PendingOps<Pending> pending_;
  std::map<OpId, OpId> state_waits_;  // our id -> TopicCondition id
};

class DdsGripper final : public Gripper, private DdsProxy {
 public:
  DdsGripper(const dds::Participant& participant, dds::EventLoop& loop, Logger log, std::string source);
  OpId set_energized(bool energize, std::chrono::nanoseconds timeout, OpCallback done) override;
  OpId wait_state(std::function<bool(const GripperSnapshot&)> predicate, std::chrono::nanoseconds timeout,
                  StateCallback done) override;
  void cancel(OpId id) override { state_.cancel(id); }

 private:
  dds::Writer<rigger_robot_GripperCommand> commands_;
  TopicCondition<rigger_robot_GripperState, GripperSnapshot> state_;
};

}  // namespace rigger::skill_sdk
