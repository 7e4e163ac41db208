#include "sim_runner.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <condition_variable>
#include <cstdio>
#include <fstream>
#include <functional>
#include <future>
#include <mutex>

#include "rigger/crane_protocol/register_map.hpp"
#include "rigger/sim/cell_geometry.hpp"

namespace rigger::cell_sim {
namespace {

using namespace std::chrono_literals;

/// Records what the runner reports.
class RecordingOutputs : public SimOutputs {
 public:
  void publish_wrench(const sim::Wrench& w, WallTime) override {
    const std::lock_guard<std::mutex> lock(mutex);
    ++wrenches;
    last_wrench = w;
  }
  void publish_robot_state(const RobotReport& r, WallTime) override {
    const std::lock_guard<std::mutex> lock(mutex);
    robot.push_back(r);
  }
  void publish_gripper_state(const GripperReport& r, WallTime) override {
    const std::lock_guard<std::mutex> lock(mutex);
    gripper.push_back(r);
  }
  void publish_motion_status(const MotionReport& r, WallTime) override {
    const std::lock_guard<std::mutex> lock(mutex);
    motions.push_back(r);
  }
  void publish_ground_truth(const GroundTruth& t, WallTime) override {
    const std::lock_guard<std::mutex> lock(mutex);
    truths.push_back(t);
  }
  void publish_status(const StatusReport& s, WallTime) override {
    {
      const std::lock_guard<std::mutex> lock(mutex);
      status.push_back(s);
    }
    status_cv.notify_all();
  }
  void publish_control_result(const ControlResult& r, WallTime) override {
    const std::lock_guard<std::mutex> lock(mutex);
    controls.push_back(r);
  }

  std::mutex mutex;
  std::condition_variable status_cv;
  std::size_t wrenches = 0;
  sim::Wrench last_wrench;
  std::vector<RobotReport> robot;
  std::vector<GripperReport> gripper;
  std::vector<MotionReport> motions;
  std::vector<GroundTruth> truths;
  std::vector<StatusReport> status;
  std::vector<ControlResult> controls;
};

/// The latest ground truth's pose of `id` (a failure when it has none).
Eigen::Isometry3d latest_truth(const RecordingOutputs& out, const std::string& id) {
  if (!out.truths.empty()) {
    for (const ObjectTruth& object : out.truths.back().objects)
      if (object.id == id) return object.pose_world_object;
  }
  ADD_FAILURE() << "no ground truth of " << id;
  return Eigen::Isometry3d::Identity();
}

CellSimConfig test_config() {
  CellSimConfig c = read_cell_sim_config(Config::parse(
      R"({"plc": {"port": 0, "link_up": false}, "camera": {"enabled": false}, "robot": {"gripper_state_rate_hz": 10}})",
      "test.json"));
  return c;
}

class SimRunnerTest : public ::testing::Test {
 protected:
  SimRunnerTest()
      : config_(test_config()), runner_(config_, sim::load_cell_geometry(config_.cell_file), out_, null_logger()) {}

  SimControlCommand control(ControlKind kind, bool on = false, double value = 0.0) {
    SimControlCommand c;
    c.kind = kind;
    c.on = on;
    c.value = value;
    c.seq = ++seq_;
    c.source = "test";
    return c;
  }
  const ControlResult& last_control() { return out_.controls.back(); }
  Eigen::Vector3d tool_position() { return out_.robot.back().state.pose_base_tool.translation(); }
  const MotionReport* motion_report(const std::string& id, MotionPhase phase) {
    for (const auto& m : out_.motions)
      if (m.motion_id == id && m.phase == phase) return &m;
    return nullptr;
  }
  TwistCommand twist_up(double speed_mps, WallTime expires, std::uint64_t seq) {
    TwistCommand t;
    t.twist_base.linear_mps = {0.0, 0.0, speed_mps};
    t.expires = expires;
    t.seq = seq;
    return t;
  }

  CellSimConfig config_;
  RecordingOutputs out_;
  SimRunner runner_;
  std::uint64_t seq_ = 0;
};

// A cell revision's moved objects: applied together, or none of them when one cannot be moved.
TEST_F(SimRunnerTest, ACellRevisionsMovesAreAppliedTogetherOrNotAtAll) {
  runner_.step_for_test(200);
  const auto truth_of = [&](const std::string& id) { return latest_truth(out_, id); };
  const auto move = [&](std::vector<ObjectMove> moves) {
    ObjectMovesCommand command;
    command.moves = std::move(moves);
    command.done = std::make_shared<std::promise<std::string>>();
    std::future<std::string> done = command.done->get_future();
    runner_.submit(std::move(command));
    runner_.step_for_test(20);
    EXPECT_EQ(done.wait_for(0s), std::future_status::ready) << "the physics thread did not answer";
    return done.get();
  };
  const Eigen::Isometry3d part = truth_of("part");
  Eigen::Isometry3d moved = part;
  moved.translation().x() -= 0.05;  // still on its table
  Eigen::Isometry3d load = truth_of("load");
  load.translation().y() += 0.1;

  const std::string refusal = move({{"part", moved}, {"load", load}});
  EXPECT_NE(refusal.find("hangs from the crane's rope"), std::string::npos) << refusal;
  EXPECT_LT((truth_of("part").translation() - part.translation()).norm(), 2e-4) << "a refused revision moved the part";

  EXPECT_EQ(move({{"part", moved}}), "");
  EXPECT_LT((truth_of("part").translation() - moved.translation()).norm(), 1e-3);

  // Moves their sender withdrew (it gave up waiting and reported them refused) are never applied later.
  ObjectMovesCommand late;
  late.moves = {{"part", part}};
  late.done = std::make_shared<std::promise<std::string>>();
  std::future<std::string> late_done = late.done->get_future();
  ASSERT_TRUE(late.claim->withdraw());
  const std::shared_ptr<CommandClaim> claim = late.claim;
  runner_.submit(std::move(late));
  runner_.step_for_test(20);
  EXPECT_THROW(late_done.get(), std::future_error) << "a withdrawn command was answered";  // dropped unanswered
  EXPECT_FALSE(claim->take());
  EXPECT_LT((truth_of("part").translation() - moved.translation()).norm(), 1e-3) << "a withdrawn move was applied";
}

// The shipped cell's document with `edit` applied, as the physics builds it (STEP models beside the file).
sim::CellGeometry revised_geometry(const CellSimConfig& config, const std::function<void(nlohmann::json&)>& edit) {
  std::ifstream in(config.cell_file, std::ios::binary);
  nlohmann::json doc = nlohmann::json::parse(in);
  edit(doc);
  return sim::parse_cell_geometry(doc.dump(), config.cell_file.string(), config.cell_file.parent_path());
}

// Two objects on the part's table beside the part: a box, and one given by its STEP model alone (part.step,
// the box centre its origin), turned a quarter round; each 1 mm above the table top (z 0.6 m).
void add_two_objects(nlohmann::json& doc) {
  doc["entities"].push_back(nlohmann::json::parse(R"({"id": "crate", "kind": "object", "parent": "world",
      "pose": {"position_m": [2.77, 1.40, 0.651], "rpy_deg": [0, 0, 0]},
      "model": {"shape": "box", "size_m": [0.1, 0.1, 0.1], "mass_kg": 2.0, "frame": "box centre"}})"));
  doc["entities"].push_back(nlohmann::json::parse(R"({"id": "part_b", "kind": "object", "parent": "world",
      "pose": {"position_m": [2.80, 1.60, 0.661], "rpy_deg": [0, 0, 90]},
      "model": {"step": "models/part.step", "mass_kg": 3.0}})"));
}

std::vector<std::string> truth_ids(const GroundTruth& truth) {
  std::vector<std::string> ids;
  for (const ObjectTruth& object : truth.objects) ids.push_back(object.id);
  return ids;
}

// A revision that adds a box and a STEP-only object, then one that removes the box: the model is built anew
// and swapped in between two steps. The cell goes on as if nothing happened (checked against a twin runner
// that never swaps, the load swinging on its rope): arm, crane and load where the twin has them; the new
// objects come to rest where they were put.
TEST_F(SimRunnerTest, AModelBuiltAnewContinuesTheCellAndRestsTheNewObjectsWherePut) {
  RecordingOutputs twin_out;
  SimRunner twin(config_, sim::load_cell_geometry(config_.cell_file), twin_out, null_logger());
  for (SimRunner* runner : {&runner_, &twin}) {
    SimControlCommand push = control(ControlKind::kSetLoadForce);
    push.vector = {60.0, -40.0, 0.0};
    runner->submit(push);
    runner->step_for_test(300);
    runner->submit(control(ControlKind::kSetLoadForce));  // zero: the load swings freely
    runner->step_for_test(200);
  }
  const auto swap = [&](sim::CellGeometry geometry) {
    ModelSwapCommand command;
    command.physics = std::make_shared<sim::CellPhysics>(geometry, config_.physics);
    command.geometry = std::move(geometry);
    command.done = std::make_shared<std::promise<ModelSwapResult>>();
    std::future<ModelSwapResult> done = command.done->get_future();
    runner_.submit(std::move(command));
    runner_.step_for_test(1);
    EXPECT_EQ(done.wait_for(0s), std::future_status::ready) << "the physics thread did not answer";
    return done.get();
  };
  const auto longest_step = [&](int steps) {
    std::chrono::nanoseconds longest{0};
    for (int i = 0; i < steps; ++i) {
      const auto t0 = std::chrono::steady_clock::now();
      runner_.step_for_test(1);
      longest = std::max<std::chrono::nanoseconds>(longest, std::chrono::steady_clock::now() - t0);
    }
    return longest;
  };
  const std::chrono::nanoseconds before = longest_step(99);
  twin.step_for_test(99);
  const ModelSwapResult added = swap(revised_geometry(config_, add_two_objects));
  ASSERT_EQ(added.refusal, "");
  const std::chrono::nanoseconds after = longest_step(100);
  twin.step_for_test(101);
  const auto ms = [](std::chrono::nanoseconds d) { return std::chrono::duration<double, std::milli>(d).count(); };
  std::printf("[ figures  ] longest step before the swap %.3f ms, the swap's step %.3f ms, longest after %.3f ms\n",
              ms(before), ms(added.swap_step), ms(after));

  // Nothing jumped: the same simulated time, arm, crane and swinging load as the twin's (to the solver's
  // tolerance: the new objects' contacts share its iterations).
  const StatusReport& s = out_.status.back();
  const StatusReport& t = twin_out.status.back();
  EXPECT_EQ(s.steps, t.steps);
  EXPECT_DOUBLE_EQ(s.sim_time_s, t.sim_time_s);
  EXPECT_LT((s.crane_position_m - t.crane_position_m).norm(), 1e-6);
  EXPECT_GT(t.crane_sway_rad.norm(), 1e-3) << "the load should swing";
  EXPECT_LT((s.crane_sway_rad - t.crane_sway_rad).norm(), 1e-6);
  EXPECT_LT((out_.robot.back().state.position_rad - twin_out.robot.back().state.position_rad).norm(), 1e-6);
  EXPECT_LT((out_.truths.back().objects[0].pose_world_object.translation() -
             twin_out.truths.back().objects[0].pose_world_object.translation())
                .norm(),
            1e-5);
  EXPECT_EQ(truth_ids(out_.truths.back()),
            (std::vector<std::string>{"load", "target", "part_fixture", "part", "crate", "part_b"}));

  // The new objects rest where they were put (1 mm above the table: they settle on it).
  runner_.step_for_test(1000);
  const auto truth_of = [&](const std::string& id) { return latest_truth(out_, id); };
  EXPECT_LT((truth_of("crate").translation() - Eigen::Vector3d(2.77, 1.40, 0.65)).norm(), 1e-3);
  EXPECT_LT((truth_of("part_b").translation() - Eigen::Vector3d(2.80, 1.60, 0.66)).norm(), 1e-3);

  // Removed: gone from the ground truth, and named once for its readers to dispose.
  const ModelSwapResult removed = swap(revised_geometry(config_, [](nlohmann::json& doc) {
    add_two_objects(doc);
    doc["entities"].erase(doc["entities"].end() - 2);  // the crate
  }));
  ASSERT_EQ(removed.refusal, "");
  runner_.step_for_test(20);
  EXPECT_EQ(truth_ids(out_.truths.back()),
            (std::vector<std::string>{"load", "target", "part_fixture", "part", "part_b"}));
  std::size_t disposals = 0;
  for (const GroundTruth& truth : out_.truths)
    disposals += std::count(truth.removed.begin(), truth.removed.end(), "crate");
  EXPECT_EQ(disposals, 1u);
  EXPECT_LT((truth_of("part_b").translation() - Eigen::Vector3d(2.80, 1.60, 0.66)).norm(), 1e-3);
}

// While the arm runs a motion the model is not swapped: refused with the reason, the cell unchanged.
TEST_F(SimRunnerTest, AModelIsNotSwappedWhileTheArmMoves) {
  MotionCommand move;
  move.motion_id = "m1";
  move.kind = MotionKind::kJoint;
  move.joint_goal_rad = sim::ready_joint_positions();
  move.joint_goal_rad[0] += 0.3;
  runner_.submit(move);
  runner_.step_for_test(50);
  ModelSwapCommand command;
  command.geometry = revised_geometry(config_, add_two_objects);
  command.physics = std::make_shared<sim::CellPhysics>(command.geometry, config_.physics);
  command.done = std::make_shared<std::promise<ModelSwapResult>>();
  std::future<ModelSwapResult> done = command.done->get_future();
  runner_.submit(std::move(command));
  runner_.step_for_test(20);
  ASSERT_EQ(done.wait_for(0s), std::future_status::ready);
  EXPECT_EQ(done.get().refusal, "motion m1 runs: the model is built anew only while the arm holds still");
  EXPECT_EQ(truth_ids(out_.truths.back()), (std::vector<std::string>{"load", "target", "part_fixture", "part"}));
}

TEST_F(SimRunnerTest, PublishesAtTheConfiguredRatesOfSimulatedTime) {
  runner_.step_for_test(1000);
  EXPECT_EQ(out_.wrenches, 1000u);      // 1 kHz
  EXPECT_EQ(out_.robot.size(), 100u);   // 100 Hz
  EXPECT_EQ(out_.status.size(), 100u);  // 100 Hz
  EXPECT_EQ(out_.truths.size(), 50u);   // 50 Hz
  // Every object of the cell file by its id; the static target where the cell file has it.
  std::vector<std::string> truth_ids;
  for (const ObjectTruth& object : out_.truths.back().objects) {
    truth_ids.push_back(object.id);
    if (object.id == "target") {
      EXPECT_TRUE(object.pose_world_object.isApprox(runner_.geometry().target.pose_world_target, 1e-9));
    }
  }
  EXPECT_EQ(truth_ids, (std::vector<std::string>{"load", "target", "part_fixture", "part"}));
  EXPECT_GE(out_.gripper.size(), 10u);  // 10 Hz and on change
  EXPECT_NEAR(out_.status.back().sim_time_s, 1.0, 1e-9);
  EXPECT_EQ(out_.status.back().steps, 1000u);
  // The external wrench excludes the gripper's weight: at rest, holding nothing, it is about zero.
  EXPECT_LT(out_.last_wrench.force_n.norm(), 2.0);
}

TEST_F(SimRunnerTest, GroundTruthCoversEveryObjectOfTheCellFile) {
  runner_.step_for_test(20);
  ASSERT_FALSE(out_.truths.empty());
  std::vector<std::string> ids;
  for (const ObjectTruth& object : out_.truths.back().objects) ids.push_back(object.id);
  EXPECT_EQ(ids, (std::vector<std::string>{"load", "target", "part_fixture", "part"}));  // the file's order
  // The target is static: exactly where the file puts it.
  EXPECT_LT((out_.truths.back().objects[1].pose_world_object.translation() - Eigen::Vector3d(3.55, 2.25, 0.95)).norm(),
            1e-9);
}

TEST_F(SimRunnerTest, StatusReportsTheCraneInTheModbusConvention) {
  runner_.step_for_test(100);
  const StatusReport& s = out_.status.back();
  const auto& crane = runner_.geometry().crane;
  EXPECT_GT(s.crane_position_m.z(), crane.rail_height_m - crane.rope_length_range_m[1]);
  EXPECT_LT(s.crane_position_m.z(), crane.rail_height_m - crane.rope_length_range_m[0]);
  EXPECT_FALSE(s.plc_link_up);
  EXPECT_EQ(s.plc_port, 0);
  EXPECT_TRUE(s.plc_status_word & crane::status_bit::kReady);
}

TEST_F(SimRunnerTest, AFreshTwistMovesTheToolAndItsExpiryStopsIt) {
  runner_.step_for_test(10);
  const Eigen::Vector3d start = tool_position();
  runner_.submit(twist_up(0.05, std::chrono::system_clock::now() + 10s, 1));
  runner_.step_for_test(500);
  const Eigen::Vector3d moved = tool_position();
  EXPECT_GT(moved.z() - start.z(), 0.01);
  EXPECT_EQ(out_.robot.back().last_command_seq, 1u);
  EXPECT_EQ(out_.robot.back().state.mode, sim::RobotMode::Twist);

  runner_.submit(twist_up(0.05, std::chrono::system_clock::now(), 2));  // expires at once
  runner_.step_for_test(400);
  const Eigen::Vector3d a = tool_position();
  runner_.step_for_test(200);
  EXPECT_LT((tool_position() - a).norm(), 1e-3) << "the arm must stop when its twist expires";
}

TEST_F(SimRunnerTest, EmergencyStopRefusesMotionUntilReleasedAndLatchesThePlcFault) {
  runner_.submit(control(ControlKind::kEstop, true));
  runner_.step_for_test(20);
  ASSERT_FALSE(out_.controls.empty());
  EXPECT_TRUE(last_control().accepted);
  EXPECT_EQ(last_control().seq, 1u);
  EXPECT_TRUE(out_.status.back().estop_pressed);
  EXPECT_EQ(out_.status.back().plc_fault_code, static_cast<std::uint16_t>(crane::FaultCode::kEmergencyStop));
  EXPECT_TRUE(out_.robot.back().estop);

  const Eigen::Vector3d start = tool_position();
  runner_.submit(twist_up(0.05, std::chrono::system_clock::now() + 10s, 5));
  MotionCommand joint;
  joint.motion_id = "m1";
  joint.kind = MotionKind::kJoint;
  joint.joint_goal_rad = sim::ready_joint_positions();
  runner_.submit(joint);
  runner_.step_for_test(300);
  EXPECT_LT((tool_position() - start).norm(), 1e-3);
  ASSERT_NE(motion_report("m1", MotionPhase::kFailed), nullptr);
  EXPECT_EQ(motion_report("m1", MotionPhase::kFailed)->code, "EMERGENCY_STOP");

  runner_.submit(control(ControlKind::kEstop, false));
  runner_.step_for_test(20);
  EXPECT_FALSE(out_.status.back().estop_pressed);
  EXPECT_FALSE(out_.robot.back().estop);
  // The crane PLC keeps its e-stop fault latched until the gateway resets it.
  EXPECT_EQ(out_.status.back().plc_fault_code, static_cast<std::uint16_t>(crane::FaultCode::kEmergencyStop));
  runner_.submit(twist_up(0.05, std::chrono::system_clock::now() + 10s, 6));
  runner_.step_for_test(300);
  EXPECT_GT((tool_position() - start).norm(), 5e-3);
}

TEST_F(SimRunnerTest, JointMotionReportsAcceptedExecutingAndSucceeded) {
  sim::JointVector goal = sim::ready_joint_positions();
  goal[0] += 0.1;
  MotionCommand joint;
  joint.motion_id = "joint-1";
  joint.kind = MotionKind::kJoint;
  joint.joint_goal_rad = goal;
  joint.timeout = 10s;
  runner_.submit(joint);
  runner_.step_for_test(4000);
  EXPECT_NE(motion_report("joint-1", MotionPhase::kAccepted), nullptr);
  EXPECT_NE(motion_report("joint-1", MotionPhase::kExecuting), nullptr);
  ASSERT_NE(motion_report("joint-1", MotionPhase::kSucceeded), nullptr);
  EXPECT_NEAR(out_.robot.back().state.position_rad[0], goal[0], 0.01);
}

TEST_F(SimRunnerTest, AMotionThatOverrunsItsTimeoutFailsAndStops) {
  sim::JointVector goal = sim::ready_joint_positions();
  goal[0] += 1.0;
  MotionCommand joint;
  joint.motion_id = "slow";
  joint.kind = MotionKind::kJoint;
  joint.joint_goal_rad = goal;
  joint.speed_fraction = 0.2;
  joint.timeout = 50ms;
  runner_.submit(joint);
  runner_.step_for_test(200);
  ASSERT_NE(motion_report("slow", MotionPhase::kFailed), nullptr);
  EXPECT_EQ(motion_report("slow", MotionPhase::kFailed)->code, "TIMEOUT");
}

TEST_F(SimRunnerTest, RefusedMotionsFailWithTheReason) {
  MotionCommand far;
  far.motion_id = "far";
  far.kind = MotionKind::kCartesian;
  far.goal_base_tool = Eigen::Isometry3d(Eigen::Translation3d(3.0, 0.0, 0.0));
  runner_.submit(far);
  MotionCommand bent;
  bent.motion_id = "bent";
  bent.kind = MotionKind::kJoint;
  bent.joint_goal_rad = sim::JointVector::Constant(3.0);  // beyond A2's 120 degrees
  runner_.submit(bent);
  runner_.step_for_test(2);
  ASSERT_NE(motion_report("far", MotionPhase::kFailed), nullptr);
  EXPECT_EQ(motion_report("far", MotionPhase::kFailed)->code, "UNREACHABLE");
  ASSERT_NE(motion_report("bent", MotionPhase::kFailed), nullptr);
  EXPECT_EQ(motion_report("bent", MotionPhase::kFailed)->code, "OUT_OF_RANGE");
}

TEST_F(SimRunnerTest, AStopEndsTheRunningMotionAndSucceedsAtRest) {
  sim::JointVector goal = sim::ready_joint_positions();
  goal[0] += 1.0;
  MotionCommand joint;
  joint.motion_id = "long";
  joint.kind = MotionKind::kJoint;
  joint.joint_goal_rad = goal;
  runner_.submit(joint);
  runner_.step_for_test(300);
  MotionCommand stop;
  stop.motion_id = "stop";
  stop.kind = MotionKind::kStop;
  runner_.submit(stop);
  runner_.step_for_test(2000);
  ASSERT_NE(motion_report("long", MotionPhase::kAborted), nullptr);
  EXPECT_EQ(motion_report("long", MotionPhase::kAborted)->code, "STOPPED");
  EXPECT_NE(motion_report("stop", MotionPhase::kSucceeded), nullptr);
}

TEST_F(SimRunnerTest, GripperCommandIsAppliedAndReportedAtOnce) {
  runner_.step_for_test(5);
  const std::size_t before = out_.gripper.size();
  runner_.submit(GripperCommand{true, 7});
  runner_.step_for_test(1);
  ASSERT_GT(out_.gripper.size(), before);
  EXPECT_TRUE(out_.gripper.back().state.energized);
  EXPECT_EQ(out_.gripper.back().last_command_seq, 7u);
}

TEST_F(SimRunnerTest, FaultInjectionIsAcknowledged) {
  runner_.submit(control(ControlKind::kSetHoldingForce, false, 100.0));
  runner_.step_for_test(10);
  EXPECT_TRUE(last_control().accepted);
  EXPECT_DOUBLE_EQ(out_.status.back().gripper_holding_force_n, 100.0);
  runner_.submit(control(ControlKind::kSetHoldingForce, false, -1.0));  // back to the cell's
  runner_.step_for_test(10);
  EXPECT_DOUBLE_EQ(out_.status.back().gripper_holding_force_n, runner_.geometry().gripper.holding_force_n);

  SimControlCommand push = control(ControlKind::kSetLoadForce);
  push.vector = {50.0, 0.0, 0.0};
  runner_.submit(push);
  runner_.step_for_test(10);
  EXPECT_TRUE(last_control().accepted);
  EXPECT_EQ(out_.status.back().load_external_force_n, Eigen::Vector3d(50.0, 0.0, 0.0));

  SimControlCommand bad = control(ControlKind::kSetLoadForce);
  bad.vector = {std::nan(""), 0.0, 0.0};
  runner_.submit(bad);
  runner_.step_for_test(1);
  EXPECT_FALSE(last_control().accepted);
  EXPECT_EQ(last_control().seq, bad.seq);
}

TEST_F(SimRunnerTest, PlcLinkGoesDownAndUp) {
  runner_.submit(control(ControlKind::kPlcLink, true));
  runner_.step_for_test(10);
  ASSERT_TRUE(last_control().accepted) << last_control().message;
  EXPECT_NE(runner_.plc_port(), 0);
  EXPECT_TRUE(out_.status.back().plc_link_up);
  runner_.submit(control(ControlKind::kPlcLink, false));
  runner_.step_for_test(10);
  EXPECT_TRUE(last_control().accepted);
  EXPECT_EQ(runner_.plc_port(), 0);
  EXPECT_FALSE(out_.status.back().plc_link_up);
}

TEST_F(SimRunnerTest, ResetReturnsToTheInitialState) {
  runner_.submit(twist_up(0.05, std::chrono::system_clock::now() + 10s, 1));
  runner_.submit(control(ControlKind::kSetHoldingForce, false, 10.0));
  runner_.step_for_test(500);
  runner_.step_for_test(10);
  const Eigen::Vector3d moved = tool_position();
  runner_.submit(control(ControlKind::kReset));
  runner_.step_for_test(10);
  EXPECT_TRUE(last_control().accepted) << last_control().message;
  EXPECT_LT(out_.status.back().sim_time_s, 0.02);
  EXPECT_GT((tool_position() - moved).norm(), 0.01);
  EXPECT_DOUBLE_EQ(out_.status.back().gripper_holding_force_n, runner_.geometry().gripper.holding_force_n);
}

TEST(SimRunner, RunsInRealTimeOnItsThreadAndStopsSafely) {
  CellSimConfig config = test_config();
  RecordingOutputs out;
  SimRunner runner(config, sim::load_cell_geometry(config.cell_file), out, null_logger());
  const auto t0 = std::chrono::steady_clock::now();
  runner.start();
  {
    std::unique_lock<std::mutex> lock(out.mutex);
    ASSERT_TRUE(out.status_cv.wait_for(lock, 10s, [&] { return out.status.size() >= 30; }));
  }
  runner.stop();
  const double wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  const std::lock_guard<std::mutex> lock(out.mutex);
  const double sim_s = out.status.back().sim_time_s;
  // 30 status reports at 100 Hz are 0.3 s of simulated time; paced, that takes at least 0.3 s.
  EXPECT_GE(wall_s, sim_s * 0.95);
  EXPECT_EQ(runner.plc_port(), 0);
}

}  // namespace
}  // namespace rigger::cell_sim
