// CalibrateCamera's FSM on fakes: the poses shown, the board measured at each, the camera solved and written
// as a dry run, then as the revision, with its record; and every way it fails without proposing a revision:
// the board not seen, poses turned about one axis, a residual over its bound, a cell without a board.
#include <gtest/gtest.h>

#include <fstream>
#include <functional>
#include <random>

#include "rigger/cell_config/cell_file.hpp"
#include "sdk_testing.hpp"
#include "skills/calibrate_camera.hpp"

namespace rigger::skill_executor {
namespace {

using namespace std::chrono_literals;
using nlohmann::json;
using testing::RunHarness;
using Kind = testing::FakeRobot::Op::Kind;

constexpr const char* kBoard = "robot/calibration_board";

// The demo cell with the test board on its robot, and the truth: the camera 20 mm and 1.5° off its drawing.
struct Cell {
  json doc;
  Eigen::Isometry3d world_base, world_camera_drawn, world_camera_true, mount;
  Cell() {
    std::ifstream in(std::string(RIGGER_SOURCE_DIR) + "/deploy/cell/simulated_cell.json");
    doc = json::parse(in);
    std::ifstream board(std::string(RIGGER_SOURCE_DIR) + "/test/data/calibration_board.json");
    for (json& entity : doc["entities"])
      if (entity["id"] == "robot") entity["calibration_board"] = json::parse(board);
    const cell::CellFile file = cell::cell_file_from_json(doc, "test");
    world_base = file.pose_root_entity("robot");
    world_camera_drawn = file.pose_root_entity("camera");
    mount = file.require("robot", "test").calibration_board->pose_tool_board;
    Eigen::Isometry3d off = Eigen::Isometry3d::Identity();
    off.linear() = Eigen::AngleAxisd(1.5 * M_PI / 180.0, Eigen::Vector3d(1, 1, 0).normalized()).toRotationMatrix();
    off.translation() = Eigen::Vector3d(0.02, 0.0, 0.0);
    world_camera_true = world_camera_drawn * off;
  }
  CellDocument document() const { return {3, doc.dump(2)}; }
};

Eigen::Isometry3d ready_tool() {
  Eigen::Isometry3d t = Eigen::Isometry3d::Identity();
  t.linear() << 0, 0, 1, 0, 1, 0, -1, 0, 0;
  t.translation() = Eigen::Vector3d(0.65, 0.25, 0.46);
  return t;
}

class CalibrateCameraTest : public ::testing::Test {
 protected:
  SkillType type_{CalibrateCameraSkill::describe(), [] { return std::make_unique<CalibrateCameraSkill>(); }};
  json params_ = {{"poses", 6}, {"requested_by", "riggerctl:test"}};
  Cell cell_;
  /// Whether the board is seen at the n-th pose measured (0-based); the tool pose the arm reports for a goal.
  std::function<bool(int)> seen_ = [](int) { return true; };
  std::function<Eigen::Isometry3d(const Eigen::Isometry3d&)> reported_ = [](const Eigen::Isometry3d& g) { return g; };
  /// The tracker answers a pose where the board is not seen with a not-tracked sample after its own 2 s wait
  /// (else it stays silent until the skill's view timeout).
  bool answer_not_seen_ = false;
  /// Noise added to the board's measured position (m).
  double noise_m_ = 0.0;
  std::mt19937 rng_{3};
  Eigen::Isometry3d goal_ = Eigen::Isometry3d::Identity();
  Eigen::Isometry3d tool_ = Eigen::Isometry3d::Identity();  // where the arm says it stands
  int measured_ = 0;

  void step(RunHarness& h) {
    const std::string state = h.state();
    if (state == "read_cell") {
      if (h.world.answer_running_cell(OpResult::success(), cell_.document())) return;
      RobotSnapshot s;
      s.frame = "robot";
      s.tool_pose = ready_tool();
      ASSERT_TRUE(h.robot.answer_state(s));
    } else if (state == "move" || state == "return") {
      ASSERT_NE(h.robot.pending(Kind::kMove), nullptr);
      goal_ = h.robot.pending(Kind::kMove)->goal.pose_frame_tool;
      EXPECT_EQ(h.robot.pending(Kind::kMove)->goal.frame, "robot");
      ASSERT_TRUE(h.robot.complete(Kind::kMove, OpResult::success()));
    } else if (state == "measure") {
      if (h.robot.pending(Kind::kState) != nullptr) {
        RobotSnapshot s;
        s.frame = "robot";
        s.tool_pose = tool_ = reported_(goal_);
        ASSERT_TRUE(h.robot.answer_state(s));
        return;
      }
      if (!seen_(measured_++)) {
        if (!answer_not_seen_) {
          h.timers.advance(6100ms);
          return;
        }
        TrackedObjectSample lost = h.tracker.sample(kBoard, false, 0.0, 2000ms);
        lost.frame = "camera";
        lost.detail = "no image of it good enough in 2 s";
        h.tracker.publish(lost);
        return;
      }
      TrackedObjectSample s = h.tracker.sample(kBoard, true, 0.9);
      s.frame = "camera";
      s.pose = cell_.world_camera_true.inverse() * cell_.world_base * tool_ * cell_.mount;
      std::normal_distribution<double> noise(0.0, noise_m_);
      if (noise_m_ > 0) s.pose.translation() += Eigen::Vector3d(noise(rng_), noise(rng_), noise(rng_));
      h.tracker.publish(s);
    } else if (state == "check" || state == "apply") {
      ASSERT_TRUE(h.world.answer_proposal(OpResult::success(), {7, json::parse(R"({"moved":[{"id":"camera"}],
          "changed":[{"id":"camera","keys":["attributes"]}]})")}));
    } else {
      FAIL() << "unexpected state " << state;
    }
  }
  void run(RunHarness& h) {
    h.run->start();
    for (int i = 0; i < 200 && !h.result; ++i) {
      step(h);
      if (HasFatalFailure()) return;
    }
  }
};

TEST_F(CalibrateCameraTest, WritesTheCameraItFoundAsADryRunThenAsTheRevision) {
  RunHarness h(type_, params_);
  run(h);
  ASSERT_TRUE(h.succeeded()) << h.describe_result();
  EXPECT_NE(h.result->message.find("cell revision 7"), std::string::npos) << h.result->message;
  ASSERT_EQ(h.world.proposals.size(), 2u);
  EXPECT_TRUE(h.world.proposals[0].dry_run);
  EXPECT_FALSE(h.world.proposals[1].dry_run);
  EXPECT_EQ(h.world.proposals[1].cell_json, h.world.proposals[0].cell_json) << "the revision is what was checked";
  EXPECT_EQ(h.world.proposals[1].who, "CalibrateCamera for riggerctl:test");
  EXPECT_NE(h.world.proposals[1].comment.find("6 poses"), std::string::npos) << h.world.proposals[1].comment;
  // The proposed camera is the true one; everything else is the running document.
  const json proposed = json::parse(h.world.proposals[1].cell_json);
  const cell::CellFile file = cell::cell_file_from_json(proposed, "proposed");
  const Eigen::Isometry3d off = cell_.world_camera_true.inverse() * file.pose_root_entity("camera");
  EXPECT_LT(off.translation().norm(), 1e-6);
  EXPECT_LT(Eigen::AngleAxisd(off.linear()).angle(), 1e-6);
  json record;
  for (const json& e : proposed["entities"])
    if (e["id"] == "camera") record = e["attributes"]["calibration"];
  EXPECT_EQ(record["requested_by"], "riggerctl:test");
  EXPECT_EQ(record["from_revision"], 3);
  EXPECT_EQ(record["poses"].size(), 6u);
  EXPECT_LT(record["residual_rms_mm"].get<double>(), 1e-3);
  json unchanged = proposed, before = cell_.doc;
  for (json* d : {&unchanged, &before})
    for (json& e : (*d)["entities"])
      if (e["id"] == "camera") e.erase("pose"), e.erase("attributes");
  EXPECT_EQ(unchanged, before);
  // The arm went back where it started.
  EXPECT_TRUE(goal_.isApprox(ready_tool(), 1e-9));
}

TEST_F(CalibrateCameraTest, ABoardNotSeenFailsWithoutARevision) {
  seen_ = [](int n) { return n < 2; };
  RunHarness h(type_, params_);
  run(h);
  EXPECT_TRUE(h.failed_with("BOARD_NOT_SEEN")) << h.describe_result();
  EXPECT_NE(h.result->message.find("at 2 of 9 poses"), std::string::npos) << h.result->message;
  EXPECT_TRUE(h.world.proposals.empty());
}

// The tracker's not-tracked answer skips a pose at once (one TRACK_ONCE, no wait for the view timeout), and spares
// stand in for the poses skipped: the calibration ends with the poses asked for, the skipped ones recorded.
TEST_F(CalibrateCameraTest, APoseNotSeenIsSkippedAtOnceAndASpareStandsInForIt) {
  seen_ = [](int n) { return n != 1 && n != 4; };
  answer_not_seen_ = true;
  RunHarness h(type_, params_);
  run(h);
  // Time never moved on: no pose waited for a timeout, and each was asked for once.
  EXPECT_EQ(h.tracker.count(TrackerRequest::kOnce), measured_);
  ASSERT_TRUE(h.succeeded()) << h.describe_result();
  const json proposed = json::parse(h.world.proposals.back().cell_json);
  json record;
  for (const json& e : proposed["entities"])
    if (e["id"] == "camera") record = e["attributes"]["calibration"];
  EXPECT_EQ(record["poses"].size(), 6u);
  EXPECT_EQ(record["skipped"], json({"pose 2: board not seen: no image of it good enough in 2 s",
                                     "pose 5: board not seen: no image of it good enough in 2 s"}));
}

// The arm stood at poses turned about the tool's z alone (whatever was asked): the camera's position along that
// axis is not determined.
TEST_F(CalibrateCameraTest, PosesTurnedAboutOneAxisFailAsDegenerate) {
  int n = 0;
  reported_ = [&n](const Eigen::Isometry3d&) {
    Eigen::Isometry3d t = ready_tool();
    t.linear() = t.linear() * Eigen::AngleAxisd(0.1 * n++, Eigen::Vector3d::UnitZ()).toRotationMatrix();
    return t;
  };
  RunHarness h(type_, params_);
  run(h);
  EXPECT_TRUE(h.failed_with("DEGENERATE_POSES")) << h.describe_result();
  EXPECT_TRUE(h.world.proposals.empty());
}

TEST_F(CalibrateCameraTest, AResidualOverItsBoundFailsWithTheFigures) {
  noise_m_ = 0.01;
  params_["max_residual_m"] = 1e-3;
  RunHarness h(type_, params_);
  run(h);
  ASSERT_TRUE(h.failed_with("RESIDUAL_TOO_LARGE")) << h.describe_result();
  EXPECT_NE(h.result->message.find("6 poses, residual "), std::string::npos) << h.result->message;
  EXPECT_NE(h.result->message.find("the cell is unchanged"), std::string::npos) << h.result->message;
  EXPECT_TRUE(h.world.proposals.empty());
}

TEST_F(CalibrateCameraTest, UnreachablePosesAreSkippedUntilTooFewAreLeft) {
  RunHarness h(type_, params_);
  h.run->start();
  ASSERT_TRUE(h.world.answer_running_cell(OpResult::success(), cell_.document()));
  RobotSnapshot s;
  s.frame = "robot";
  s.tool_pose = ready_tool();
  ASSERT_TRUE(h.robot.answer_state(s));
  for (int i = 0; i < 20 && h.state() == "move"; ++i)
    ASSERT_TRUE(
        h.robot.complete(Kind::kMove, OpResult::failure("MOTION_FAILED", "UNREACHABLE: tool goal unreachable")));
  ASSERT_EQ(h.state(), "return");
  ASSERT_TRUE(h.robot.complete(Kind::kMove, OpResult::success()));
  EXPECT_TRUE(h.failed_with("POSES_UNREACHABLE")) << h.describe_result();
  EXPECT_TRUE(h.world.proposals.empty());
}

TEST_F(CalibrateCameraTest, ACellWithoutABoardOrTheCameraIsUnavailable) {
  for (const char* missing : {"board", "camera"}) {
    json doc = cell_.doc;
    for (json& e : doc["entities"]) {
      if (e["id"] == "robot" && std::string(missing) == "board") e.erase("calibration_board");
    }
    json params = params_;
    if (std::string(missing) == "camera") params["camera"] = "crane";
    RunHarness h(type_, params);
    h.run->start();
    ASSERT_TRUE(h.world.answer_running_cell(OpResult::success(), {3, doc.dump()}));
    EXPECT_TRUE(h.failed_with("CELL_UNAVAILABLE")) << h.describe_result();
    EXPECT_EQ(h.robot.moves, 0);
  }
}

TEST_F(CalibrateCameraTest, ARefusedRevisionFailsWithTheWorldModelsCode) {
  RunHarness h(type_, params_);
  h.run->start();
  for (int i = 0; i < 200 && !h.result && h.state() != "check"; ++i) step(h);
  ASSERT_EQ(h.state(), "check");
  ASSERT_TRUE(h.world.answer_proposal(OpResult::failure("HELD_BY_TASK", "\"camera\" is held by task t")));
  EXPECT_TRUE(h.failed_with("WORLD_UPDATE_REJECTED")) << h.describe_result();
  EXPECT_EQ(h.world.proposals.size(), 1u) << "nothing applied after a refused dry run";
}

TEST_F(CalibrateCameraTest, AShutdownWhileMovingStopsTheArm) {
  RunHarness h(type_, params_);
  h.run->start();
  for (int i = 0; i < 10 && h.state() != "move"; ++i) step(h);
  ASSERT_EQ(h.state(), "move");
  h.run->shutdown("test");
  ASSERT_TRUE(h.robot.complete(Kind::kStop, OpResult::success()));
  EXPECT_TRUE(h.stopped()) << h.describe_result();
}

TEST_F(CalibrateCameraTest, APauseWhileMovingStopsTheArmAndResumeAsksForTheSamePose) {
  RunHarness h(type_, params_);
  h.run->start();
  for (int i = 0; i < 10 && h.state() != "move"; ++i) step(h);
  ASSERT_EQ(h.state(), "move");
  const Eigen::Isometry3d asked = h.robot.pending(Kind::kMove)->goal.pose_frame_tool;
  ASSERT_TRUE(h.run->pause(true));
  ASSERT_TRUE(h.robot.complete(Kind::kStop, OpResult::success()));
  EXPECT_EQ(h.robot.pending(Kind::kMove), nullptr) << "no motion while paused";
  ASSERT_TRUE(h.run->pause(false));
  ASSERT_NE(h.robot.pending(Kind::kMove), nullptr);
  EXPECT_TRUE(h.robot.pending(Kind::kMove)->goal.pose_frame_tool.isApprox(asked));
  run(h);
  EXPECT_TRUE(h.succeeded()) << h.describe_result();
}

}  // namespace
}  // namespace rigger::skill_executor
