#include "rigger/protocol/access.hpp"

#include <algorithm>
#include <initializer_list>
#include <sstream>

#include "rigger/protocol/admittance.hpp"
#include "rigger/protocol/cad.hpp"
#include "rigger/protocol/catalog.hpp"
#include "rigger/protocol/crane.hpp"
#include "rigger/protocol/operator.hpp"
#include "rigger/protocol/robot.hpp"
#include "rigger/protocol/safety.hpp"
#include "rigger/protocol/sim.hpp"
#include "rigger/protocol/skill.hpp"
#include "rigger/protocol/system.hpp"
#include "rigger/protocol/task.hpp"
#include "rigger/protocol/vision.hpp"
#include "rigger/protocol/world.hpp"

namespace rigger::protocol {
namespace {

using Names = std::vector<std::string>;

// What one building block of a program opens, as (publish, subscribe).
struct Part {
  Names publish, subscribe;
};

template <typename... Topics>
Names names(const Topics&... topics) {
  return {topics.name...};
}

Part join(std::initializer_list<Part> parts) {
  Part all;
  for (const auto& p : parts) {
    all.publish.insert(all.publish.end(), p.publish.begin(), p.publish.end());
    all.subscribe.insert(all.subscribe.end(), p.subscribe.begin(), p.subscribe.end());
  }
  for (auto* v : {&all.publish, &all.subscribe}) {
    std::sort(v->begin(), v->end());
    v->erase(std::unique(v->begin(), v->end()), v->end());
  }
  return all;
}

// Every process announces itself and most watch who is alive (run_service, ServiceDirectory).
Part service() {
  return {names(system::kServiceState), names(system::kServiceState)};
}
// An executor endpoint (skill_executor, monitor_host, scripted_executor): commands in, events out.
Part executor() {
  return {names(skill::kEvent, skill::kExecutors), names(skill::kCommand)};
}
// world_client::WorldClient opens its query and update pairs whether or not the program updates.
Part world_client() {
  return {names(world::kQuery, world::kUpdate), names(world::kReply, world::kUpdateResult)};
}
// common/cell_follower: a reader of the cell file that follows its revisions (rigger/world/cell).
Part cell_follower() {
  return {{}, names(world::kCell, world::kCellModel)};
}
// Who may propose cell revisions (riggerctl cell, the console's programmer, the CalibrateCamera skill).
Part cell_client() {
  return {names(world::kCellRequest), names(world::kCellReply)};
}
// The software safe stop as a device reads it (safety::SafeStopListener).
Part safe_stop_listener() {
  return {{}, names(safety::kStop)};
}
// The task views of the user tools: submit, command, follow, read the journal.
Part task_client() {
  return {names(task::kRecipe, task::kCommand, task::kJournalQuery, operator_ui::kResponse),
          names(task::kStatus, task::kNodeStatus, task::kJournalReply, skill::kExecutors, operator_ui::kPrompt,
                operator_ui::kResponse)};
}
// The skill executor's device proxies (common/skill_sdk/src/dds_*devices.cpp), each switched on by
// the executor's configuration (deploy/config/*-skills.json).
Part robot_device() {
  return {names(robot::kCmdMotion), names(robot::kState, robot::kMotionStatus)};
}
Part gripper_device() {
  return {names(robot::kGripperCmd), names(robot::kGripperState)};
}
Part crane_device() {
  return {names(crane::kControl), names(crane::kState)};
}
Part tracker_device() {
  return {names(vision::kTrackerCommand), names(vision::kTrackerPose)};
}
Part admittance_device() {
  return {names(admittance::kCommand), names(admittance::kState)};
}
Part operator_device() {
  return {names(operator_ui::kPrompt), names(operator_ui::kResponse)};
}

Names every_topic() {
  Names all;
  for (const auto& t : catalog()) all.push_back(t.name);
  return all;
}

Grant grant(const char* identity, const char* description, std::initializer_list<Part> parts) {
  Part p = join(parts);
  return {identity, description, std::move(p.publish), std::move(p.subscribe)};
}

std::vector<Grant> build() {
  std::vector<Grant> t;
  // The services of deploy/compose.yaml.
  t.push_back(grant("cell_sim", "the simulated cell (robot, gripper, camera drivers; PLC emulator over Modbus)",
                    {service(),
                     safe_stop_listener(),
                     cell_follower(),
                     {names(robot::kWrench, robot::kState, robot::kMotionStatus, robot::kGripperState,
                            vision::kCameraImage, vision::kCameraDepth, vision::kCameraInfo, sim::kGroundTruth,
                            sim::kEvent, sim::kStatus),
                      names(robot::kCmdTwist, robot::kCmdMotion, robot::kGripperCmd, sim::kControl)}}));
  t.push_back(
      grant("crane_gateway", "the only bridge to the crane PLC (Modbus TCP, outside DDS)",
            {service(), safe_stop_listener(), {names(crane::kState), names(crane::kCmdVelocity, crane::kControl)}}));
  t.push_back(grant(
      "world_model", "the world model",
      {service(),
       {names(world::kEntity, world::kChange, world::kReply, world::kUpdateResult, world::kCell, world::kCellModel,
              world::kCellReply),
        names(world::kQuery, world::kUpdate, world::kCellRequest, vision::kTrackerPose, skill::kExecutors)}}));
  t.push_back(
      grant("cad", "the CAD service", {service(), cell_follower(), {names(cad::kReply), names(cad::kRequest)}}));
  t.push_back(grant(
      "vision_tracker", "the vision tracker",
      {service(),
       cell_follower(),
       {names(vision::kTrackerPose),
        names(vision::kCameraImage, vision::kCameraDepth, vision::kCameraInfo, vision::kTrackerCommand,
              world::kEntity, robot::kState)}}));
  t.push_back(grant("admittance_control", "admittance control: the only writer of robot twists and crane velocities",
                    {service(),
                     safe_stop_listener(),
                     cell_follower(),
                     {names(admittance::kState, robot::kCmdTwist, crane::kCmdVelocity, crane::kControl),
                      names(admittance::kCommand, robot::kWrench, robot::kState, operator_ui::kJoystick,
                            vision::kTrackerPose, crane::kState)}}));
  // A real robot's driver behind ROS 2 (services/ros2_bridge): the bridge's own ROS 2 topics (rt/…) depend on
  // the cell's configuration and are granted from deploy/security/ros2.grants (make-pki --extra).
  t.push_back(grant("ros2_bridge",
                    "the ROS 2 bridge: a ROS 2 driver's wrench, joint states, camera images and camera info in, "
                    "rigger's twist out to MoveIt Servo",
                    {service(),
                     safe_stop_listener(),
                     {names(robot::kWrench, robot::kState, vision::kCameraImage, vision::kCameraInfo),
                      names(robot::kCmdTwist)}}));
  t.push_back(
      grant("monitor_host", "the monitors (timer, force, yank)", {service(), executor(), {{}, names(robot::kWrench)}}));
  // cell_client: CalibrateCamera writes the camera's calibrated pose as a cell revision.
  t.push_back(grant("robot-skills", "the robot's skill executor (deploy/config/robot-skills.json)",
                    {service(), executor(), world_client(), robot_device(), gripper_device(), crane_device(),
                     tracker_device(), admittance_device(), operator_device(), cell_client()}));
  t.push_back(grant("perception-skills", "the perception skill executor (Localize)",
                    {service(), executor(), world_client(), tracker_device()}));
  t.push_back(grant("operator-skills", "the operator skill executor (Screw)",
                    {service(), executor(), world_client(), operator_device()}));
  t.push_back(grant("task_controller", "the task controller",
                    {service(),
                     world_client(),
                     {names(task::kStatus, task::kNodeStatus, task::kJournalReply, skill::kCommand,
                            operator_ui::kPrompt, safety::kStop),
                      names(task::kRecipe, task::kCommand, task::kJournalQuery, skill::kEvent, skill::kExecutors,
                            operator_ui::kResponse)}}));
  // It reads the responses too: a prompt answered elsewhere (console, riggerctl) is not answered again.
  t.push_back(grant("scripted_operator", "the scripted operator (demo and tests)",
                    {service(), {names(operator_ui::kResponse), names(operator_ui::kPrompt, operator_ui::kResponse)}}));
  // The user tools.
  t.push_back(grant("console", "the web console: its users act through this one identity",
                    {service(),
                     task_client(),
                     world_client(),
                     cell_follower(),
                     cell_client(),
                     // world::kEntity: the 3D cell's poses.
                     {names(cad::kRequest), names(cad::kReply, robot::kState, robot::kWrench, crane::kState,
                                                  admittance::kState, world::kEntity)}}));
  t.push_back(grant("riggerctl",
                    "riggerctl, the operator's command line (run, cancel, operator, jog, estop, crane "
                    "reset, sim, cell); reads every topic (riggerctl echo)",
                    {service(),
                     task_client(),
                     cell_client(),
                     {names(operator_ui::kJoystick, safety::kStop, crane::kControl, sim::kControl), every_topic()}}));
  t.push_back(
      grant("rigger-compose", "the supervisor and rigger-compose ps/restart: service states only", {service()}));
  // Tests, benchmarks, recorders.
  t.push_back(grant("observer", "read-only: tests, recorders, dashboards", {service(), {{}, every_topic()}}));
  t.push_back(grant("echo", "the echo service (benchmarks)",
                    {service(), {names(system::kEchoReply, system::kPeerView), names(system::kEchoRequest)}}));
  t.push_back(grant("bench", "the echo benchmark's client",
                    {service(), {names(system::kEchoRequest), names(system::kEchoReply, system::kPeerView)}}));
  return t;
}

}  // namespace

const std::vector<Grant>& access_table() {
  static const std::vector<Grant> table = build();
  return table;
}

const Grant* find_grant(const std::string& identity) {
  for (const auto& g : access_table())
    if (g.identity == identity) return &g;
  return nullptr;
}

std::string access_table_lines() {
  std::ostringstream out;
  for (const auto& g : access_table()) {
    for (const auto& t : g.publish) out << g.identity << " publish " << t << '\n';
    for (const auto& t : g.subscribe) out << g.identity << " subscribe " << t << '\n';
  }
  return out.str();
}

}  // namespace rigger::protocol
