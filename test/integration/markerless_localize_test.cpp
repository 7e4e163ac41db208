// Localize without markers on real processes: cell_sim renders the marker-free demo cell
// (deploy/cell/simulated_cell_markerless.json) with MuJoCo and a structured-light sensor's depth noise;
// the vision tracker answers TRACK_ONCE_MODEL from the depth image and the objects' STEP models; the
// perception-skills executor runs Localize with method "model". What must hold on every run: Localize
// either succeeds and the world model then holds the object's pose within 5 mm and 1 degree of the
// simulator's truth (the insertion's tolerance; measured 2.7-3.9 mm, decision 0032), or it fails with the
// tracker's code for a refused fit (NOT_FOUND, LOW_FIT, AMBIGUOUS) and the world model still holds the object
// as not localized: never a wrong pose. (In this cell the camera sees the hanging load and the tall target
// nearly edge-on from above, and the localizer refuses some frames: docs/decisions/0027-localize-by-model.md.)
// An object without a model fails at once with NO_MODEL.
#include <cmath>
#include <fstream>
#include <map>
#include <optional>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "cell_sim_test_support.hpp"
#include "rigger/dds/conversions.hpp"
#include "rigger/dds/pubsub.hpp"
#include "rigger/protocol/sim.hpp"
#include "rigger/protocol/skill.hpp"
#include "rigger/world_client/world_client.hpp"
#include "skill_command_support.hpp"

namespace rigger::testing {
namespace {

using namespace std::chrono_literals;

// The insertion's tolerance.
constexpr double kPositionToleranceM = 0.005;
constexpr double kRotationToleranceDeg = 1.0;

double angle_deg(const Eigen::Matrix3d& a, const Eigen::Matrix3d& b) {
  return Eigen::AngleAxisd(a.transpose() * b).angle() * 180.0 / M_PI;
}

struct Event {
  std::string node;
  rigger_skill_SkillEventKind kind;
  std::string code, message;
};

class MarkerlessLocalizeTest : public MultiProcessTest {
 protected:
  void SetUp() override {
    auto& p = cell_.participant();
    commands_.emplace(p, protocol::skill::kCommand);
    events_.emplace(p, protocol::skill::kEvent);
    truths_.emplace(p, protocol::sim::kGroundTruth, dds::qos::sensor_stream().keep_last(64));
    cell_.loop().on_data(*events_, [this] {
      events_->take([this](const rigger_skill_SkillEvent& e, const dds_sample_info_t&) {
        events_seen_.push_back({dds::to_string(e.node_id), e.kind, dds::to_string(e.code), dds::to_string(e.message)});
      });
    });
    cell_.loop().on_data(*truths_, [this] {
      truths_->take([this](const rigger_vision_TrackedPose& t, const dds_sample_info_t&) {
        truth_[dds::to_string(t.object_id)] = dds::to_domain(t.pose.pose);
      });
    });
    const std::string cell_file = repo_file("deploy/cell/simulated_cell_markerless.json");
    const std::string dir = cell_.log_dir();
    std::ofstream(dir + "/cell_sim.json") << nlohmann::json{
        {"cell_file", cell_file},
        {"plc", {{"port", 0}}},
        {"camera",
         {{"renderer", "mujoco"},
          {"depth_noise", {{"stddev_at_1m_m", 0.001}, {"grazing_deg", 80.0}, {"edge_gap_m", 0.01}}}}}};
    std::ofstream(dir + "/world_model.json") << nlohmann::json{{"cell_config", cell_file}};
    std::ofstream(dir + "/vision_tracker.json") << nlohmann::json{{"cell_file", cell_file}};
    cell_.start("cell_sim", "cell_sim", {"--config", dir + "/cell_sim.json"});
    cell_.start("world_model", "world_model",
                {"--config", dir + "/world_model.json", "--db", dir + "/world_model.sqlite"});
    cell_.start("vision_tracker", "vision_tracker", {"--config", dir + "/vision_tracker.json"});
    cell_.start("perception-skills", "skill_executor",
                {"--id", "perception-skills", "--config", repo_file("deploy/config/perception-skills.json")});
    ASSERT_TRUE(cell_.wait_ready({"cell_sim", "world_model", "vision_tracker", "perception-skills"}, 60s))
        << cell_.logs();
    ASSERT_TRUE(commands_->wait_for_readers(1, 10s));
    ASSERT_TRUE(events_->wait_for_writers(1, 10s));
    world_.emplace(p, cell_.loop(), null_logger(), "markerless-localize-test");
    ASSERT_TRUE(cell_.wait_until([&] { return world_->connected(); }, 10s));
  }
  void TearDown() override {
    world_.reset();
    MultiProcessTest::TearDown();
  }

  /// Runs Localize on `object` with method model; the run's final event.
  std::optional<Event> localize(const std::string& object) {
    const std::string node = "localize-" + object;
    const nlohmann::json params = {{"object", object}, {"method", "model"}, {"timeout_s", 10.0}};
    EXPECT_EQ(write_skill_command(*commands_, {"perception-skills", "t1", node, "Localize", rigger_skill_SKILL_START,
                                               params.dump(), "test", ++seq_}),
              DDS_RETCODE_OK);
    auto find = [&]() -> std::optional<Event> {
      for (const Event& e : events_seen_)
        if (e.node == node && ends_run(e.kind)) return e;
      return std::nullopt;
    };
    cell_.wait_until([&] { return find().has_value(); }, 40s);
    return find();
  }

  /// The world model's pose of `object` in the world, and whether it is localized.
  std::optional<world_client::Reply> world_pose(const std::string& object) {
    std::optional<world_client::Reply> reply;
    world_->pose(object, "world", 3s, [&](const world_client::Reply& r) { reply = r; });
    cell_.wait_until([&] { return reply.has_value(); }, 5s);
    return reply;
  }

  void expect_near(const std::string& object, const Eigen::Isometry3d& truth) {
    const std::optional<world_client::Reply> reply = world_pose(object);
    ASSERT_TRUE(reply && reply->ok) << object << ": " << (reply ? reply->code + " " + reply->message : "no reply");
    EXPECT_TRUE(reply->localized) << object;
    const double position_m = (reply->pose.translation() - truth.translation()).norm();
    const double rotation_deg = angle_deg(reply->pose.linear(), truth.linear());
    std::cout << object << ": " << position_m * 1e3 << " mm, " << rotation_deg << " deg from the truth\n";
    EXPECT_LT(position_m, kPositionToleranceM) << object;
    EXPECT_LT(rotation_deg, kRotationToleranceDeg) << object << ": the pose nearest the prior among the symmetric ones";
  }

  std::optional<dds::Writer<rigger_skill_SkillCommand>> commands_;
  std::optional<dds::Reader<rigger_skill_SkillEvent>> events_;
  std::optional<dds::Reader<rigger_vision_TrackedPose>> truths_;
  std::optional<world_client::WorldClient> world_;
  std::vector<Event> events_seen_;
  std::map<std::string, Eigen::Isometry3d> truth_;
  std::uint64_t seq_ = 0;
};

TEST_F(MarkerlessLocalizeTest, LocalizeByModelStoresAPoseWithinFiveMillimetresAndOneDegreeOrFailsWithACode) {
  ASSERT_TRUE(cell_.wait_until([&] { return truth_.count("load") != 0; }, 20s)) << "no ground truth of the load";
  // The load hangs still from the crane; the target is static (its truth is the cell file's pose).
  const std::map<std::string, Eigen::Isometry3d> truths = {
      {"load", truth_.at("load")}, {"target", Eigen::Translation3d(3.55, 2.25, 0.95) * Eigen::Isometry3d::Identity()}};
  for (const auto& [object, truth] : truths) {
    const std::optional<Event> e = localize(object);
    ASSERT_TRUE(e) << object << ": Localize did not end\n" << cell_.logs();
    std::cout << object << ": " << e->code << " " << e->message << " (truth at " << truth.translation().transpose()
              << " m)\n";
    if (e->kind == rigger_skill_SKILL_EVENT_SUCCESS) {
      expect_near(object, truth);
      continue;
    }
    ASSERT_EQ(e->kind, rigger_skill_SKILL_EVENT_FAILURE) << object;
    EXPECT_TRUE(e->code == "NOT_FOUND" || e->code == "LOW_FIT" || e->code == "AMBIGUOUS")
        << object << ": the depth images reached the tracker and were searched, so a refused fit: " << e->code << " "
        << e->message;
    const std::optional<world_client::Reply> reply = world_pose(object);
    ASSERT_TRUE(reply && reply->ok) << object;
    EXPECT_FALSE(reply->localized) << object << ": a refused fit must not localize it";
  }
}

TEST_F(MarkerlessLocalizeTest, AnEntityWithoutAModelFailsAtOnceWithNoModel) {
  const std::optional<Event> e = localize("robot");
  ASSERT_TRUE(e);
  EXPECT_EQ(e->kind, rigger_skill_SKILL_EVENT_FAILURE);
  EXPECT_EQ(e->code, "NO_MODEL") << e->message;
}

}  // namespace
}  // namespace rigger::testing
