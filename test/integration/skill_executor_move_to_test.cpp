// skill_executor as a real process running MoveTo: the test is the controller (raw SkillCommands) and
// the robot driver (answers rigger/robot/cmd_motion on motion_status, publishes rigger/robot/state).
#include <algorithm>
#include <fstream>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "rigger/dds/conversions.hpp"
#include "rigger/dds/pubsub.hpp"
#include "rigger/protocol/robot.hpp"
#include "rigger/protocol/skill.hpp"
#include "rigger/testing/cell.hpp"
#include "skill_command_support.hpp"

namespace rigger::testing {
namespace {

using namespace std::chrono_literals;

constexpr const char* kExecutor = "robot-skills";

struct Event {
  rigger_skill_SkillEventKind kind;
  std::string code, message;
};
struct Motion {
  std::string id;
  rigger_robot_MotionKind kind;
  Eigen::Isometry3d pose;
  std::string frame;
};

class SkillExecutorMoveToTest : public MultiProcessTest {
 protected:
  void SetUp() override {
    auto& p = cell_.participant();
    commands_ = std::make_unique<dds::Writer<rigger_skill_SkillCommand>>(p, protocol::skill::kCommand);
    events_ = std::make_unique<dds::Reader<rigger_skill_SkillEvent>>(p, protocol::skill::kEvent);
    motions_ = std::make_unique<dds::Reader<rigger_robot_MotionCommand>>(p, protocol::robot::kCmdMotion);
    status_ = std::make_unique<dds::Writer<rigger_robot_MotionStatus>>(p, protocol::robot::kMotionStatus);
    state_ = std::make_unique<dds::Writer<rigger_robot_RobotState>>(p, protocol::robot::kState);
    cell_.loop().on_data(*events_, [this] {
      events_->take([this](const rigger_skill_SkillEvent& e, const dds_sample_info_t&) {
        events_seen_.push_back({e.kind, dds::to_string(e.code), dds::to_string(e.message)});
      });
    });
    cell_.loop().on_data(*motions_, [this] {
      motions_->take([this](const rigger_robot_MotionCommand& c, const dds_sample_info_t&) { on_motion(c); });
    });
    // The robot driver's state stream, 100 Hz.
    state_timer_ = cell_.loop().every(10ms, [this] {
      rigger_robot_RobotState s{};
      const std::string frame = "robot";
      s.header.stamp = dds::wire_now();
      s.header.frame_id = dds::wire_string(frame);
      s.tool_pose = dds::to_wire(tool_pose_);
      state_->write(s);
    });
    cell_.start(kExecutor, "skill_executor", {"--id", kExecutor});
    ASSERT_TRUE(cell_.wait_ready({kExecutor}, 10s));
    ASSERT_TRUE(commands_->wait_for_readers(1, 10s));
    ASSERT_TRUE(status_->wait_for_readers(1, 10s));
    ASSERT_TRUE(events_->wait_for_writers(1, 10s));  // the executor's replies are volatile
  }
  void TearDown() override {
    cell_.loop().cancel(state_timer_);
    MultiProcessTest::TearDown();
  }

  void on_motion(const rigger_robot_MotionCommand& c) {
    motions_seen_.push_back({dds::to_string(c.motion_id), c.kind, dds::to_domain(c.pose_goal), dds::to_string(c.header.frame_id)});
    const Motion& m = motions_seen_.back();
    if (m.kind == rigger_robot_MOTION_STOP) {
      if (answer_stops_) report(m.id, rigger_robot_MOTION_SUCCEEDED);
      return;
    }
    report(m.id, rigger_robot_MOTION_ACCEPTED);
    if (!motion_outcome_) return;  // the motion "runs" until the test decides
    if (*motion_outcome_ == rigger_robot_MOTION_SUCCEEDED) tool_pose_ = m.pose;
    report(m.id, *motion_outcome_, *motion_outcome_ == rigger_robot_MOTION_FAILED ? "IK_FAILED" : "");
  }
  void report(const std::string& motion_id, rigger_robot_MotionState state, const std::string& code = "") {
    rigger_robot_MotionStatus s{};
    const std::string message = "test driver";
    s.header.stamp = dds::wire_now();
    s.motion_id = dds::wire_string(motion_id);
    s.state = state;
    s.code = dds::wire_string(code);
    s.message = dds::wire_string(message);
    status_->write(s);
  }
  void send(const std::string& node, rigger_skill_SkillCommandKind kind, const nlohmann::json& params = {}) {
    ASSERT_EQ(write_skill_command(*commands_, {kExecutor, "t1", node, "MoveTo", kind, params.dump(), "test", ++seq_}),
              DDS_RETCODE_OK);
  }
  /// The event that ended the run (SUCCESS, FAILURE, STOPPED), waiting up to `timeout`.
  const Event* final_event(std::chrono::milliseconds timeout = 5s) {
    auto find = [this]() -> const Event* {
      for (const auto& e : events_seen_)
        if (ends_run(e.kind)) return &e;
      return nullptr;
    };
    cell_.wait_until([&] { return find() != nullptr; }, timeout);
    return find();
  }
  int motions_of(rigger_robot_MotionKind kind) const {
    int n = 0;
    for (const auto& m : motions_seen_) n += m.kind == kind;
    return n;
  }

  static nlohmann::json goal() {
    return {{"goal", {{"position_m", {0.5, 0.1, 0.4}}, {"rpy_deg", {180.0, 0.0, 0.0}}}}, {"timeout_s", 5.0}};
  }

  std::unique_ptr<dds::Writer<rigger_skill_SkillCommand>> commands_;
  std::unique_ptr<dds::Reader<rigger_skill_SkillEvent>> events_;
  std::unique_ptr<dds::Reader<rigger_robot_MotionCommand>> motions_;
  std::unique_ptr<dds::Writer<rigger_robot_MotionStatus>> status_;
  std::unique_ptr<dds::Writer<rigger_robot_RobotState>> state_;
  dds::EventLoop::TimerId state_timer_ = 0;
  Eigen::Isometry3d tool_pose_ = Eigen::Isometry3d::Identity();
  std::optional<rigger_robot_MotionState> motion_outcome_ = rigger_robot_MOTION_SUCCEEDED;
  bool answer_stops_ = true;
  std::vector<Event> events_seen_;
  std::vector<Motion> motions_seen_;
  std::uint64_t seq_ = 0;
};

TEST_F(SkillExecutorMoveToTest, MovesToTheGoalAndSucceeds) {
  send("move", rigger_skill_SKILL_START, goal());
  const Event* e = final_event();
  ASSERT_NE(e, nullptr);
  EXPECT_EQ(e->kind, rigger_skill_SKILL_EVENT_SUCCESS) << e->code << " " << e->message;
  ASSERT_EQ(motions_of(rigger_robot_MOTION_CARTESIAN), 1);
  EXPECT_NEAR(motions_seen_[0].pose.translation().x(), 0.5, 1e-9);
  EXPECT_EQ(motions_seen_[0].frame, "robot");
  EXPECT_EQ(motions_of(rigger_robot_MOTION_STOP), 0);
  int progress = 0;
  for (const auto& ev : events_seen_) progress += ev.kind == rigger_skill_SKILL_EVENT_PROGRESS ? 1 : 0;
  EXPECT_GE(progress, 1) << "no PROGRESS before the result";
}

TEST_F(SkillExecutorMoveToTest, AFailedMotionIsReportedAfterTheRobotStopped) {
  motion_outcome_ = rigger_robot_MOTION_FAILED;
  send("move", rigger_skill_SKILL_START, goal());
  const Event* e = final_event();
  ASSERT_NE(e, nullptr);
  EXPECT_EQ(e->kind, rigger_skill_SKILL_EVENT_FAILURE);
  EXPECT_EQ(e->code, "MOTION_FAILED");
  EXPECT_NE(e->message.find("IK_FAILED"), std::string::npos) << e->message;
  EXPECT_EQ(motions_of(rigger_robot_MOTION_STOP), 1);
}

TEST_F(SkillExecutorMoveToTest, ShutdownWhileMovingIsStoppedOnlyOnceTheRobotIsAtRest) {
  motion_outcome_.reset();  // the motion never ends by itself
  answer_stops_ = false;
  send("move", rigger_skill_SKILL_START, goal());
  ASSERT_TRUE(cell_.wait_until([&] { return motions_of(rigger_robot_MOTION_CARTESIAN) == 1; }, 5s));
  send("move", rigger_skill_SKILL_SHUTDOWN);
  ASSERT_TRUE(cell_.wait_until([&] { return motions_of(rigger_robot_MOTION_STOP) == 1; }, 5s));
  // The robot has not confirmed the stop: no STOPPED may arrive (this waits on the test's loop).
  EXPECT_EQ(final_event(300ms), nullptr);
  const std::string stop_id = motions_seen_.back().id;
  report(stop_id, rigger_robot_MOTION_SUCCEEDED);
  const Event* e = final_event();
  ASSERT_NE(e, nullptr);
  EXPECT_EQ(e->kind, rigger_skill_SKILL_EVENT_STOPPED);
}

TEST_F(SkillExecutorMoveToTest, BadParamsFailWithThePointer) {
  send("bad", rigger_skill_SKILL_START, {{"goal", {{"position_m", {0.5, 0.1}}}}, {"speed_scale", 3.0}});
  const Event* e = final_event();
  ASSERT_NE(e, nullptr);
  EXPECT_EQ(e->code, "BAD_PARAMS");
  EXPECT_NE(e->message.find("/params/speed_scale"), std::string::npos) << e->message;
  EXPECT_EQ(motions_seen_.size(), 0u);
}

TEST(SkillExecutorDescribe, PrintsTheConfiguredLibraryAndExitsZero) {
  const std::string dir = ::testing::TempDir();
  ChildProcess ok("skill_executor", {"--describe"}, {}, dir + "/describe_ok.log");
  auto status = ok.wait(10s);
  ASSERT_TRUE(status);
  EXPECT_TRUE(status->ok()) << status->describe();
  const auto library = nlohmann::json::parse(ok.log());
  EXPECT_EQ(library.at("library_version"), 1);
  std::vector<std::string> names;  // every built-in skill, sorted by name
  for (const auto& skill : library.at("skills")) names.push_back(skill.at("name").get<std::string>());
  EXPECT_NE(std::find(names.begin(), names.end(), "MoveTo"), names.end());

  const std::string config = dir + "/bad_skills.json";
  { std::ofstream(config) << R"({"skills": ["MoveTo", "Fly"]})"; }
  ChildProcess bad("skill_executor", {"--describe", "--config", config}, {}, dir + "/describe_bad.log");
  status = bad.wait(10s);
  ASSERT_TRUE(status);
  EXPECT_EQ(status->code, 2);
  EXPECT_NE(bad.log().find("unknown skill 'Fly'"), std::string::npos) << bad.log();
}

}  // namespace
}  // namespace rigger::testing
