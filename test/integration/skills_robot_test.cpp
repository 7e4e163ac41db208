// The gripper skills on real processes: cell_sim (robot driver, magnetic gripper, physics), world_model
// and skill_executor hosting AttachRobotToLoad and Release; the test is the controller (raw
// SkillCommands on rigger/skill/command, events from rigger/skill/event). The load is marked localized
// at its true pose (rigger/sim/ground_truth → rigger/world/update), as Localize would.
// - AttachRobotToLoad succeeds with the magnet holding in the physics; run again while holding (a
//   retry) it releases, retreats and grasps again; Release lets go and retreats;
// - a slip injected while the hold is verified (weak magnet + a pull away) fails GRASP_LOST;
// - a SHUTDOWN during the slow final approach stops the robot and answers STOPPED.
// These run without the crane gateway (check_crane = false). When crane_gateway is built too,
// SkillsRobotCraneTest adds it: AttachRobotToLoad checks the crane's health, and with the PLC link cut
// Release refuses with CRANE_FAULT and the magnet keeps holding.
#include <fstream>
#include <iostream>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "cell_sim_test_support.hpp"
#include "rigger/protocol/crane.hpp"
#include "rigger/protocol/robot.hpp"
#include "rigger/protocol/sim.hpp"
#include "rigger/protocol/skill.hpp"
#include "rigger/world_client/world_client.hpp"
#include "skill_command_support.hpp"

namespace rigger::testing {
namespace {

using namespace std::chrono_literals;

constexpr const char* kExecutor = "robot-skills";

struct Event {
  rigger_skill_SkillEventKind kind;
  std::string node, code, message;
  WallTime received;
};
struct RobotView {
  WallTime stamp{};
  Eigen::Isometry3d tool = Eigen::Isometry3d::Identity();
  bool moving = false;
};
struct GripperView {
  WallTime stamp{};
  bool energized = false, contact = false, holding = false;
};

class SkillsRobotTest : public MultiProcessTest {
 protected:
  void SetUp() override {
    auto& p = cell_.participant();
    sim_ = std::make_unique<SimChannel>(cell_);
    commands_ = std::make_unique<dds::Writer<rigger_skill_SkillCommand>>(p, protocol::skill::kCommand);
    events_ = std::make_unique<dds::Reader<rigger_skill_SkillEvent>>(p, protocol::skill::kEvent);
    robot_ = std::make_unique<dds::Reader<rigger_robot_RobotState>>(p, protocol::robot::kState);
    gripper_ = std::make_unique<dds::Reader<rigger_robot_GripperState>>(p, protocol::robot::kGripperState);
    truth_ = std::make_unique<dds::Reader<rigger_vision_TrackedPose>>(p, protocol::sim::kGroundTruth);
    cell_.loop().on_data(*events_, [this] {
      events_->take([this](const rigger_skill_SkillEvent& e, const dds_sample_info_t&) {
        events_seen_.push_back({e.kind, dds::to_string(e.node_id), dds::to_string(e.code), dds::to_string(e.message),
                                std::chrono::system_clock::now()});
      });
    });
    cell_.loop().on_data(*robot_, [this] {
      robot_->take([this](const rigger_robot_RobotState& s, const dds_sample_info_t&) {
        robot_states_.push_back({dds::to_domain(s.header.stamp), dds::to_domain(s.tool_pose), s.moving});
      });
    });
    cell_.loop().on_data(*gripper_, [this] {
      gripper_->take([this](const rigger_robot_GripperState& s, const dds_sample_info_t&) {
        gripper_states_.push_back({dds::to_domain(s.header.stamp), s.energized, s.contact, s.holding});
      });
    });
    cell_.loop().on_data(*truth_, [this] {
      truth_->take([this](const rigger_vision_TrackedPose& t, const dds_sample_info_t&) {
        if (dds::to_string(t.object_id) == "load") load_truth_ = dds::to_domain(t.pose.pose);
      });
    });

    const std::string plc_port = std::to_string(free_tcp_port());
    cell_.start("cell_sim", "cell_sim", {"--config", repo_file("deploy/config/cell_sim.json"), "--plc-port", plc_port});
    if (with_crane()) {
      ASSERT_TRUE(cell_.wait_ready({"cell_sim"}, 30s)) << cell_.logs();
      cell_.start("crane_gateway", "crane_gateway",
                  {"--config", repo_file("deploy/config/crane_gateway.json"), "--plc-port", plc_port});
    }
    cell_.start("world_model", "world_model",
                {"--id", "world_model", "--config", repo_file("deploy/config/world_model.json"), "--db",
                 cell_.log_dir() + "/world.sqlite"});
    const std::string config = cell_.log_dir() + "/robot_skills.json";
    {
      std::ofstream(config) << R"({"executor_id": "robot-skills", "skills": ["AttachRobotToLoad", "Release"],
        "tracker": false, "admittance": false, "operator": false, "crane": )"
                            << (with_crane() ? "true" : "false") << "}";
    }
    cell_.start(kExecutor, "skill_executor", {"--id", kExecutor, "--config", config});
    std::vector<std::string> services{"cell_sim", "world_model", kExecutor};
    if (with_crane()) services.push_back("crane_gateway");
    ASSERT_TRUE(cell_.wait_ready(services, 30s)) << cell_.logs();
    ASSERT_TRUE(commands_->wait_for_readers(1, 10s));
    ASSERT_TRUE(events_->wait_for_writers(1, 10s));  // the executor's replies are volatile

    // Localize the load at its true pose, as the Localize skill would.
    world_ = std::make_unique<world_client::WorldClient>(p, cell_.loop(), null_logger(), "skills-robot-test");
    ASSERT_TRUE(cell_.wait_until([&] { return world_->connected() && load_truth_.has_value(); }, 10s));
    std::optional<world_client::Reply> reply;
    world_->update_pose("load", "world", *load_truth_, std::chrono::system_clock::now(), 1.0, true, 3s,
                        [&](const world_client::Reply& r) { reply = r; });
    ASSERT_TRUE(cell_.wait_until([&] { return reply.has_value(); }, 5s));
    ASSERT_TRUE(reply->ok) << reply->code << ": " << reply->message;
    ASSERT_TRUE(cell_.wait_until([&] { return !robot_states_.empty() && !gripper_states_.empty(); }, 5s));
  }

  /// Also runs the crane gateway, and the executor offers the crane's health to the skills.
  virtual bool with_crane() const { return false; }

  void send(const std::string& node, const std::string& skill, rigger_skill_SkillCommandKind kind,
            const nlohmann::json& params = nlohmann::json::object()) {
    ASSERT_EQ(write_skill_command(*commands_, {kExecutor, "t1", node, skill, kind, params.dump(), "test", ++seq_}),
              DDS_RETCODE_OK);
  }
  /// The event that ended `node`'s run (SUCCESS, FAILURE, STOPPED), waiting up to `timeout`.
  const Event* final_event(const std::string& node, std::chrono::milliseconds timeout) {
    auto find = [&]() -> const Event* {
      for (const auto& e : events_seen_)
        if (e.node == node && ends_run(e.kind)) return &e;
      return nullptr;
    };
    cell_.wait_until([&] { return find() != nullptr; }, timeout);
    return find();
  }
  /// Waits for a PROGRESS of `node` whose message contains `text`.
  bool wait_progress(const std::string& node, const std::string& text, std::chrono::milliseconds timeout) {
    return cell_.wait_until(
        [&] {
          for (const auto& e : events_seen_)
            if (e.node == node && e.kind == rigger_skill_SKILL_EVENT_PROGRESS &&
                e.message.find(text) != std::string::npos)
              return true;
          return false;
        },
        timeout);
  }
  static nlohmann::json attach_params() {
    return {{"grasp", "load/grasp_side"}, {"approach", "load/pre_grasp"}, {"check_crane", false}, {"timeout_s", 60.0}};
  }
  std::string describe(const Event* e) const { return e ? e->code + ": " + e->message : "no event\n" + cell_.logs(); }

  std::unique_ptr<SimChannel> sim_;
  std::unique_ptr<dds::Writer<rigger_skill_SkillCommand>> commands_;
  std::unique_ptr<dds::Reader<rigger_skill_SkillEvent>> events_;
  std::unique_ptr<dds::Reader<rigger_robot_RobotState>> robot_;
  std::unique_ptr<dds::Reader<rigger_robot_GripperState>> gripper_;
  std::unique_ptr<dds::Reader<rigger_vision_TrackedPose>> truth_;
  std::unique_ptr<world_client::WorldClient> world_;
  std::optional<Eigen::Isometry3d> load_truth_;
  std::vector<Event> events_seen_;
  std::vector<RobotView> robot_states_;
  std::vector<GripperView> gripper_states_;
  std::uint64_t seq_ = 0;
};

TEST_F(SkillsRobotTest, AttachHoldsTheLoadInThePhysicsAndReleaseLetsGoAndRetreats) {
  const auto t0 = std::chrono::system_clock::now();
  send("attach", "AttachRobotToLoad", rigger_skill_SKILL_START, attach_params());
  const Event* attach = final_event("attach", 90s);
  ASSERT_NE(attach, nullptr) << cell_.logs();
  ASSERT_EQ(attach->kind, rigger_skill_SKILL_EVENT_SUCCESS) << describe(attach);
  const double attach_s = std::chrono::duration<double>(attach->received - t0).count();
  std::cout << "AttachRobotToLoad: SUCCESS after " << attach_s << " s (" << attach->message << ")\n";
  RecordProperty("attach_ms", static_cast<int>(attach_s * 1000.0));
  // The physics holds the load: a gripper state after the SUCCESS says so.
  const WallTime after_attach = std::chrono::system_clock::now();
  ASSERT_TRUE(cell_.wait_until([&] { return gripper_states_.back().stamp > after_attach; }, 5s));
  EXPECT_TRUE(gripper_states_.back().holding);
  EXPECT_TRUE(gripper_states_.back().energized);

  // A retry while holding (as after a slip): releases, retreats to the approach pose, grasps again.
  const std::size_t gripper_before_retry = gripper_states_.size();
  const auto t_retry = std::chrono::system_clock::now();
  send("attach-again", "AttachRobotToLoad", rigger_skill_SKILL_START, attach_params());
  const Event* again = final_event("attach-again", 90s);
  ASSERT_NE(again, nullptr) << cell_.logs();
  ASSERT_EQ(again->kind, rigger_skill_SKILL_EVENT_SUCCESS) << describe(again);
  std::cout << "AttachRobotToLoad retry (release, retreat, grasp again): SUCCESS after "
            << std::chrono::duration<double>(again->received - t_retry).count() << " s\n";
  bool released_in_between = false;
  for (std::size_t i = gripper_before_retry; i < gripper_states_.size(); ++i)
    released_in_between = released_in_between || !gripper_states_[i].energized;
  EXPECT_TRUE(released_in_between) << "the retry did not release first";
  const WallTime after_retry = std::chrono::system_clock::now();
  ASSERT_TRUE(cell_.wait_until([&] { return gripper_states_.back().stamp > after_retry; }, 5s));
  EXPECT_TRUE(gripper_states_.back().holding);
  const Eigen::Isometry3d tool_at_grasp = robot_states_.back().tool;

  const auto t1 = std::chrono::system_clock::now();
  send("release", "Release", rigger_skill_SKILL_START, {{"check_crane", false}});
  const Event* release = final_event("release", 30s);
  ASSERT_NE(release, nullptr) << cell_.logs();
  ASSERT_EQ(release->kind, rigger_skill_SKILL_EVENT_SUCCESS) << describe(release);
  std::cout << "Release: SUCCESS after " << std::chrono::duration<double>(release->received - t1).count() << " s\n";
  const WallTime after_release = std::chrono::system_clock::now();
  ASSERT_TRUE(cell_.wait_until(
      [&] { return robot_states_.back().stamp > after_release && gripper_states_.back().stamp > after_release; }, 5s));
  EXPECT_FALSE(gripper_states_.back().holding);
  EXPECT_FALSE(gripper_states_.back().energized);
  // Retreated 0.10 m (the default) back along the tool's -z.
  const Eigen::Vector3d moved = robot_states_.back().tool.translation() - tool_at_grasp.translation();
  const Eigen::Vector3d tool_z = tool_at_grasp.linear().col(2);
  std::cout << "Release retreat: " << moved.norm() * 1000.0 << " mm, along tool -z " << -moved.dot(tool_z) * 1000.0
            << " mm\n";
  EXPECT_NEAR(-moved.dot(tool_z), 0.10, 0.01);
  EXPECT_FALSE(robot_states_.back().moving);
}

TEST_F(SkillsRobotTest, ASlipWhileTheHoldIsVerifiedIsGraspLost) {
  auto params = attach_params();
  params["verify_s"] = 8.0;  // a window long enough to inject the slip in
  send("attach", "AttachRobotToLoad", rigger_skill_SKILL_START, params);
  ASSERT_TRUE(wait_progress("attach", "verifying the hold", 90s)) << describe(final_event("attach", 0ms));
  ASSERT_TRUE(gripper_states_.back().holding);
  const auto injected = std::chrono::system_clock::now();
  const auto weak = sim_->send(rigger_sim_SIM_SET_HOLDING_FORCE, false, 50.0);
  ASSERT_TRUE(weak.has_value() && weak->first);
  // Pull the load away from the robot (world +x: the robot stands at smaller x).
  const auto pull = sim_->send(rigger_sim_SIM_SET_LOAD_FORCE, false, 0.0, Eigen::Vector3d(300.0, 0.0, 0.0));
  ASSERT_TRUE(pull.has_value() && pull->first);
  const Event* e = final_event("attach", 15s);
  ASSERT_NE(e, nullptr) << cell_.logs();
  EXPECT_EQ(e->kind, rigger_skill_SKILL_EVENT_FAILURE);
  EXPECT_EQ(e->code, "GRASP_LOST") << describe(e);
  std::cout << "slip injected (holding force 50 N, then 300 N pull) -> " << e->code << " "
            << ms_between(injected, e->received) << " ms after the first injection\n";
  EXPECT_FALSE(gripper_states_.back().holding);
  sim_->send(rigger_sim_SIM_SET_LOAD_FORCE, false, 0.0, Eigen::Vector3d::Zero());
}

TEST_F(SkillsRobotTest, ShutdownDuringTheApproachStopsTheRobotAndAnswersStopped) {
  auto params = attach_params();
  params["approach_speed_m_per_s"] = 0.005;  // 0.1 m in ~20 s
  send("attach", "AttachRobotToLoad", rigger_skill_SKILL_START, params);
  ASSERT_TRUE(wait_progress("attach", "approaching the grasp frame", 90s)) << describe(final_event("attach", 0ms));
  ASSERT_TRUE(cell_.wait_until([&] { return robot_states_.back().moving; }, 5s)) << "the approach never started";
  send("attach", "AttachRobotToLoad", rigger_skill_SKILL_SHUTDOWN);
  const auto shutdown_sent = std::chrono::system_clock::now();
  const Event* e = final_event("attach", 10s);
  ASSERT_NE(e, nullptr) << cell_.logs();
  EXPECT_EQ(e->kind, rigger_skill_SKILL_EVENT_STOPPED) << describe(e);
  std::cout << "SHUTDOWN -> STOPPED after " << ms_between(shutdown_sent, e->received) << " ms\n";
  // The robot is at rest: a state sample after STOPPED says not moving, and the tool stays put.
  const WallTime after = std::chrono::system_clock::now();
  ASSERT_TRUE(cell_.wait_until([&] { return robot_states_.back().stamp > after; }, 5s));
  EXPECT_FALSE(robot_states_.back().moving);
  const Eigen::Vector3d at_stop = robot_states_.back().tool.translation();
  const WallTime later = after + 300ms;
  cell_.wait_until([&] { return robot_states_.back().stamp > later; }, 5s);
  EXPECT_LT((robot_states_.back().tool.translation() - at_stop).norm(), 1e-3);
  // The magnet was energized at the approach pose and is left as it is.
  EXPECT_TRUE(gripper_states_.back().energized);
}

#ifdef RIGGER_WITH_CRANE_GATEWAY
// With the crane gateway: AttachRobotToLoad checks the crane's health (check_crane = true, the default)
// and grasps; with the PLC link cut (the gateway reports link_ok = false) Release refuses to let go.
class SkillsRobotCraneTest : public SkillsRobotTest {
 protected:
  bool with_crane() const override { return true; }
};

TEST_F(SkillsRobotCraneTest, AttachChecksTheCraneAndReleaseRefusesWhileTheCraneReportsAFault) {
  dds::Reader<rigger_crane_CraneState> crane(cell_.participant(), protocol::crane::kState);
  std::optional<bool> link_ok;
  cell_.loop().on_data(crane, [&] {
    crane.take([&](const rigger_crane_CraneState& c, const dds_sample_info_t&) { link_ok = c.link_ok; });
  });
  send("attach", "AttachRobotToLoad", rigger_skill_SKILL_START,
       {{"grasp", "load/grasp_side"}, {"approach", "load/pre_grasp"}, {"timeout_s", 60.0}});
  const Event* attach = final_event("attach", 90s);
  ASSERT_NE(attach, nullptr) << cell_.logs();
  ASSERT_EQ(attach->kind, rigger_skill_SKILL_EVENT_SUCCESS) << describe(attach);

  const auto cut = sim_->send(rigger_sim_SIM_PLC_LINK, false);
  ASSERT_TRUE(cut.has_value() && cut->first);
  ASSERT_TRUE(cell_.wait_until([&] { return link_ok.has_value() && !*link_ok; }, 10s))
      << "the gateway never saw the cut";
  send("release", "Release", rigger_skill_SKILL_START);
  const Event* release = final_event("release", 10s);
  ASSERT_NE(release, nullptr) << cell_.logs();
  EXPECT_EQ(release->kind, rigger_skill_SKILL_EVENT_FAILURE);
  EXPECT_EQ(release->code, "CRANE_FAULT") << describe(release);
  std::cout << "Release with the PLC link cut: " << release->code << " (" << release->message << ")\n";
  const WallTime after = std::chrono::system_clock::now();
  ASSERT_TRUE(cell_.wait_until([&] { return gripper_states_.back().stamp > after; }, 5s));
  EXPECT_TRUE(gripper_states_.back().holding) << "the magnet let go although the crane reports a fault";
}
#endif

}  // namespace
}  // namespace rigger::testing
