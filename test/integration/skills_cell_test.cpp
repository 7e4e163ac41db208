// Localize and Screw on real processes: world_model (the simulated cell's entities and CAD features) and
// the shipped perception-skills and operator-skills executors (deploy/config/*.json); the test plays the
// controller (raw SkillCommands), the vision tracker (answers TRACK_ONCE on rigger/tracker/pose) and the
// operator (answers rigger/operator/prompt on rigger/operator/response).
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "rigger/dds/conversions.hpp"
#include "rigger/dds/pubsub.hpp"
#include "rigger/operator_protocol/prompt.hpp"
#include "rigger/protocol/operator.hpp"
#include "rigger/protocol/skill.hpp"
#include "rigger/protocol/vision.hpp"
#include "rigger/testing/cell.hpp"
#include "rigger/world_client/world_client.hpp"
#include "skill_command_support.hpp"

namespace rigger::testing {
namespace {

using namespace std::chrono_literals;

std::string repo(const std::string& relative) {
  return std::string(RIGGER_SOURCE_DIR) + "/" + relative;
}

struct Event {
  std::string executor, node;
  rigger_skill_SkillEventKind kind;
  std::string code, message;
};
struct Prompt {
  std::string id, kind;
  bool active;
  nlohmann::json details;
};

class SkillsCellTest : public MultiProcessTest {
 protected:
  void SetUp() override {
    auto& p = cell_.participant();
    commands_ = std::make_unique<dds::Writer<rigger_skill_SkillCommand>>(p, protocol::skill::kCommand);
    events_ = std::make_unique<dds::Reader<rigger_skill_SkillEvent>>(p, protocol::skill::kEvent);
    tracker_commands_ =
        std::make_unique<dds::Reader<rigger_vision_TrackerCommand>>(p, protocol::vision::kTrackerCommand);
    poses_ = std::make_unique<dds::Writer<rigger_vision_TrackedPose>>(p, protocol::vision::kTrackerPose);
    prompts_ = std::make_unique<dds::Reader<rigger_operator_ui_OperatorPrompt>>(p, protocol::operator_ui::kPrompt);
    responses_ =
        std::make_unique<dds::Writer<rigger_operator_ui_OperatorResponse>>(p, protocol::operator_ui::kResponse);
    cell_.loop().on_data(*events_, [this] {
      events_->take([this](const rigger_skill_SkillEvent& e, const dds_sample_info_t&) {
        events_seen_.push_back({dds::to_string(e.executor_id), dds::to_string(e.node_id), e.kind,
                                dds::to_string(e.code), dds::to_string(e.message)});
      });
    });
    cell_.loop().on_data(*tracker_commands_, [this] {
      tracker_commands_->take([this](const rigger_vision_TrackerCommand& c, const dds_sample_info_t&) {
        ++track_once_;
        if (c.kind == rigger_vision_TRACK_ONCE) publish_pose(dds::to_string(c.object_id));
      });
    });
    cell_.loop().on_data(*prompts_, [this] {
      prompts_->take([this](const rigger_operator_ui_OperatorPrompt& prompt, const dds_sample_info_t& info) {
        if (!info.valid_data) return;
        prompts_seen_.push_back({dds::to_string(prompt.prompt_id), dds::to_string(prompt.kind), prompt.active,
                                 nlohmann::json::parse(dds::to_string(prompt.details_json))});
        if (prompt.active && !answers_.empty()) {
          respond(prompts_seen_.back().id, answers_.front());
          answers_.erase(answers_.begin());
        }
      });
    });
    cell_.start("world_model", "world_model",
                {"--id", "world_model", "--config", repo("deploy/config/world_model.json"), "--db",
                 cell_.log_dir() + "/world.sqlite"});
    for (const char* id : {"perception-skills", "operator-skills"})
      cell_.start(id, "skill_executor", {"--id", id, "--config", repo(std::string("deploy/config/") + id + ".json")});
    ASSERT_TRUE(cell_.wait_ready({"world_model", "perception-skills", "operator-skills"}, 30s)) << cell_.logs();
    ASSERT_TRUE(commands_->wait_for_readers(2, 10s));
    ASSERT_TRUE(events_->wait_for_writers(2, 10s));  // the executors' replies are volatile
    ASSERT_TRUE(poses_->wait_for_readers(1, 10s));
    ASSERT_TRUE(responses_->wait_for_readers(1, 10s));
    world_ = std::make_unique<world_client::WorldClient>(p, cell_.loop(), null_logger(), "skills-cell-test");
    ASSERT_TRUE(cell_.wait_until([&] { return world_->connected(); }, 10s));
  }
  void TearDown() override {
    world_.reset();
    MultiProcessTest::TearDown();
  }

  void publish_pose(const std::string& object) {
    rigger_vision_TrackedPose out{};
    const std::string frame = "world";
    out.header.stamp = dds::wire_now();
    out.header.frame_id = dds::wire_string(frame);
    out.object_id = dds::wire_string(object);
    out.tracked = true;
    out.quality = 0.9;
    out.pose.pose = dds::to_wire(tracked_pose_);
    poses_->write(out);
  }
  void respond(const std::string& prompt_id, const std::string& answer) {
    operator_protocol::write_response(*responses_, prompt_id, answer, "test-operator", "");
  }
  void start(const std::string& executor, const std::string& node, const std::string& skill,
             const nlohmann::json& params) {
    ASSERT_EQ(write_skill_command(
                  *commands_, {executor, "t1", node, skill, rigger_skill_SKILL_START, params.dump(), "test", ++seq_}),
              DDS_RETCODE_OK);
  }
  const Event* final_event(const std::string& node, std::chrono::milliseconds timeout = 15s) {
    auto find = [&]() -> const Event* {
      for (const auto& e : events_seen_)
        if (e.node == node && ends_run(e.kind)) return &e;
      return nullptr;
    };
    cell_.wait_until([&] { return find() != nullptr; }, timeout);
    return find();
  }

  std::unique_ptr<dds::Writer<rigger_skill_SkillCommand>> commands_;
  std::unique_ptr<dds::Reader<rigger_skill_SkillEvent>> events_;
  std::unique_ptr<dds::Reader<rigger_vision_TrackerCommand>> tracker_commands_;
  std::unique_ptr<dds::Writer<rigger_vision_TrackedPose>> poses_;
  std::unique_ptr<dds::Reader<rigger_operator_ui_OperatorPrompt>> prompts_;
  std::unique_ptr<dds::Writer<rigger_operator_ui_OperatorResponse>> responses_;
  std::unique_ptr<world_client::WorldClient> world_;
  Eigen::Isometry3d tracked_pose_ = Eigen::Isometry3d::Identity();
  std::vector<Event> events_seen_;
  std::vector<Prompt> prompts_seen_;
  std::vector<std::string> answers_;
  int track_once_ = 0;
  std::uint64_t seq_ = 0;
};

TEST_F(SkillsCellTest, LocalizeStoresTheTrackedPoseInTheWorldModel) {
  tracked_pose_.translation() = Eigen::Vector3d(3.60, 1.70, 1.25);
  start("perception-skills", "localize-load", "Localize", {{"object", "load"}, {"timeout_s", 5.0}});
  const Event* e = final_event("localize-load");
  ASSERT_NE(e, nullptr);
  ASSERT_EQ(e->kind, rigger_skill_SKILL_EVENT_SUCCESS) << e->code << " " << e->message;
  EXPECT_GE(track_once_, 1);
  std::optional<world_client::Reply> reply;
  world_->pose("load", "world", 3s, [&](const world_client::Reply& r) { reply = r; });
  ASSERT_TRUE(cell_.wait_until([&] { return reply.has_value(); }, 5s));
  ASSERT_TRUE(reply->ok) << reply->code << " " << reply->message;
  EXPECT_TRUE(reply->localized);
  EXPECT_NEAR(reply->pose.translation().x(), 3.60, 1e-9);
  EXPECT_NEAR(reply->pose.translation().z(), 1.25, 1e-9);
}

TEST_F(SkillsCellTest, LocalizeOfAnUnknownObjectIsRejectedByTheWorldModel) {
  start("perception-skills", "localize-ghost", "Localize", {{"object", "ghost"}, {"timeout_s", 5.0}});
  const Event* e = final_event("localize-ghost");
  ASSERT_NE(e, nullptr);
  EXPECT_EQ(e->kind, rigger_skill_SKILL_EVENT_FAILURE);
  EXPECT_EQ(e->code, "WORLD_UPDATE_REJECTED") << e->message;
  EXPECT_NE(e->message.find("UNKNOWN_ENTITY"), std::string::npos) << e->message;
}

TEST_F(SkillsCellTest, ScrewPromptsEachHoleWithTheWorldModelsDataAndSucceedsOnDone) {
  answers_ = {"done", "done"};
  start("operator-skills", "screw", "Screw", {{"holes", {"target/h1", "target/h2"}}});
  const Event* e = final_event("screw");
  ASSERT_NE(e, nullptr);
  ASSERT_EQ(e->kind, rigger_skill_SKILL_EVENT_SUCCESS) << e->code << " " << e->message;
  ASSERT_TRUE(cell_.wait_until([&] { return prompts_seen_.size() >= 4; }, 5s));
  ASSERT_EQ(prompts_seen_.size(), 4u);
  const Prompt& first = prompts_seen_[0];
  EXPECT_TRUE(first.active);
  EXPECT_EQ(first.kind, "screw");
  EXPECT_EQ(first.details["hole"], "h1");
  EXPECT_EQ(first.details["screw_type"], "M12x40");  // deploy/cell/simulated_cell.json
  EXPECT_DOUBLE_EQ(first.details["torque_nm"].get<double>(), 60.0);
  // Hole h1 at (-0.15, -0.10, 0) in the target, the target at (3.55, 2.25, 0.95) in the world.
  EXPECT_NEAR(first.details["position_m"][0].get<double>(), 3.40, 1e-9);
  EXPECT_NEAR(first.details["position_m"][1].get<double>(), 2.15, 1e-9);
  EXPECT_NEAR(first.details["position_m"][2].get<double>(), 0.95, 1e-9);
  EXPECT_FALSE(prompts_seen_[1].active) << "the answered prompt is withdrawn";
  EXPECT_EQ(prompts_seen_[2].details["hole"], "h2");
  EXPECT_FALSE(prompts_seen_[3].active);
}

TEST_F(SkillsCellTest, ScrewFailsWhenTheOperatorReportsAFailedHole) {
  answers_ = {"failed"};
  start("operator-skills", "screw-failed", "Screw", {{"holes", {"target/h3"}}, {"torque_nm", 70.0}});
  const Event* e = final_event("screw-failed");
  ASSERT_NE(e, nullptr);
  EXPECT_EQ(e->kind, rigger_skill_SKILL_EVENT_FAILURE);
  EXPECT_EQ(e->code, "SCREW_FAILED") << e->message;
  ASSERT_FALSE(prompts_seen_.empty());
  EXPECT_DOUBLE_EQ(prompts_seen_[0].details["torque_nm"].get<double>(), 70.0) << "the params' torque overrides";
  ASSERT_TRUE(cell_.wait_until([&] { return prompts_seen_.size() >= 2; }, 5s));
  EXPECT_FALSE(prompts_seen_.back().active);
}

TEST_F(SkillsCellTest, ScrewOfAHoleTheTargetDoesNotHaveFailsBeforePrompting) {
  start("operator-skills", "screw-h9", "Screw", {{"holes", {"target/h9"}}});
  const Event* e = final_event("screw-h9");
  ASSERT_NE(e, nullptr);
  EXPECT_EQ(e->kind, rigger_skill_SKILL_EVENT_FAILURE);
  EXPECT_EQ(e->code, "UNKNOWN_FEATURE") << e->message;
  EXPECT_TRUE(prompts_seen_.empty());
}

}  // namespace
}  // namespace rigger::testing
