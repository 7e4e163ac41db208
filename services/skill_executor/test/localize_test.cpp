// Localize's FSM on fakes: detection (quality, stamp, retries), the world update and its verdicts,
// bad params, missing devices, and shutdown from every state.
#include <gtest/gtest.h>

#include "run_steps.hpp"
#include "sdk_testing.hpp"
#include "skills/localize.hpp"

namespace rigger::skill_executor {
namespace {

using namespace std::chrono_literals;
using testing::RunHarness;

class LocalizeTest : public ::testing::Test {
 protected:
  SkillType type_{LocalizeSkill::describe(), [] { return std::make_unique<LocalizeSkill>(); }};
  nlohmann::json params_ = {{"object", "load"}, {"timeout_s", 3.0}};
};

TEST_F(LocalizeTest, SuccessSendsTrackOnceAndStoresAGoodFreshPose) {
  RunHarness h(type_, params_);
  h.run->start();
  EXPECT_EQ(h.state(), "detect");
  ASSERT_EQ(h.tracker.count(TrackerRequest::kOnce), 1);
  EXPECT_EQ(h.tracker.commands[0].second, "load");
  // A pose of another object, and an old image of ours, do not count.
  h.tracker.publish(h.tracker.sample("target", true, 0.9));
  h.tracker.publish(h.tracker.sample("load", true, 0.9, -100ms));
  EXPECT_EQ(h.state(), "detect");
  const auto good = h.tracker.sample("load", true, 0.8);
  h.tracker.publish(good);
  EXPECT_EQ(h.state(), "update");
  EXPECT_EQ(h.tracker.watches(), 0u) << "the pose watch ends with detect";
  const auto* update = h.world.pending_update();
  ASSERT_NE(update, nullptr);
  EXPECT_EQ(update->entity, "load");
  EXPECT_EQ(update->parent, "world");
  EXPECT_EQ(update->stamp, good.stamp) << "the observation time is the image's";
  EXPECT_DOUBLE_EQ(update->quality, 0.8);
  EXPECT_NEAR(update->pose.translation().y(), 2.0, 1e-12);
  EXPECT_FALSE(h.result) << "not before the world model accepted";
  ASSERT_TRUE(h.world.answer_update(OpResult::success("ACCEPTED")));
  ASSERT_TRUE(h.succeeded());
  EXPECT_EQ(h.timers.pending(), 0u);
}

TEST_F(LocalizeTest, LowQualityOrLostPosesAskTheTrackerAgain) {
  RunHarness h(type_, params_);
  h.run->start();
  h.tracker.publish(h.tracker.sample("load", true, 0.3));  // below the default 0.5
  EXPECT_EQ(h.state(), "detect");
  EXPECT_EQ(h.tracker.count(TrackerRequest::kOnce), 2) << "the tracker went idle after one image: ask again";
  h.tracker.publish(h.tracker.sample("load", false, 0.0));
  EXPECT_EQ(h.tracker.count(TrackerRequest::kOnce), 3);
  // Without any pose, TRACK_ONCE is repeated every retry period.
  h.timers.advance(LocalizeSkill::kRetryPeriod);
  EXPECT_EQ(h.tracker.count(TrackerRequest::kOnce), 4);
  h.tracker.publish(h.tracker.sample("load", true, 0.51));
  EXPECT_EQ(h.state(), "update");
}

TEST_F(LocalizeTest, MinQualityIsAParameter) {
  params_["min_quality"] = 0.95;
  RunHarness h(type_, params_);
  h.run->start();
  h.tracker.publish(h.tracker.sample("load", true, 0.9));
  EXPECT_EQ(h.state(), "detect");
  h.tracker.publish(h.tracker.sample("load", true, 0.96));
  EXPECT_EQ(h.state(), "update");
}

TEST_F(LocalizeTest, NoGoodPoseWithinTheTimeoutIsNotDetected) {
  RunHarness h(type_, params_);
  h.run->start();
  h.tracker.publish(h.tracker.sample("load", true, 0.2));
  h.timers.advance(3s);
  ASSERT_TRUE(h.failed_with("NOT_DETECTED")) << (h.result ? h.result->code : "no result");
  EXPECT_NE(h.result->message.find("quality 0.20"), std::string::npos) << h.result->message;
  EXPECT_EQ(h.timers.pending(), 0u);
  EXPECT_EQ(h.tracker.watches(), 0u);
}

TEST_F(LocalizeTest, ARejectedUpdateFailsWithTheWorldModelsCode) {
  RunHarness h(type_, params_);
  h.run->start();
  h.tracker.publish(h.tracker.sample("load", true, 0.9));
  ASSERT_TRUE(h.world.answer_update(OpResult::failure("UNKNOWN_ENTITY", "no entity \"load\"")));
  ASSERT_TRUE(h.failed_with("WORLD_UPDATE_REJECTED"));
  EXPECT_NE(h.result->message.find("UNKNOWN_ENTITY"), std::string::npos);
}

TEST_F(LocalizeTest, AnUnreachableWorldModelIsWorldUnreachable) {
  RunHarness h(type_, params_);
  h.run->start();
  h.tracker.publish(h.tracker.sample("load", true, 0.9));
  ASSERT_TRUE(h.world.answer_update(OpResult::failure("WORLD_UNREACHABLE", "no reply")));
  EXPECT_TRUE(h.failed_with("WORLD_UNREACHABLE"));
}

TEST_F(LocalizeTest, StampBackwardsDetectsAgainAFewTimesThenFails) {
  RunHarness h(type_, params_);
  h.run->start();
  for (int attempt = 1; attempt <= LocalizeSkill::kMaxUpdateAttempts; ++attempt) {
    h.tracker.publish(h.tracker.sample("load", true, 0.9));
    ASSERT_EQ(h.state(), "update") << attempt;
    ASSERT_TRUE(h.world.answer_update(OpResult::failure("STAMP_BACKWARDS", "older than the last change")));
    if (attempt < LocalizeSkill::kMaxUpdateAttempts) {
      EXPECT_EQ(h.state(), "detect") << attempt;
    }
  }
  ASSERT_TRUE(h.failed_with("WORLD_UPDATE_REJECTED"));
  EXPECT_NE(h.result->message.find("STAMP_BACKWARDS"), std::string::npos);
}

TEST_F(LocalizeTest, ByModelAsksTheTrackerAgainAfterEachRefusalAndStoresTheFittingPose) {
  params_["method"] = "model";
  params_["timeout_s"] = 10.0;
  RunHarness h(type_, params_);
  h.run->start();
  ASSERT_EQ(h.tracker.count(TrackerRequest::kOnceByModel), 1);
  EXPECT_EQ(h.tracker.count(TrackerRequest::kOnce), 0) << "no marker request";
  TrackedObjectSample refused = h.tracker.sample("load", false, 0.0);
  refused.status = "LOW_FIT";
  h.tracker.publish(refused);
  EXPECT_EQ(h.state(), "detect");
  EXPECT_EQ(h.tracker.count(TrackerRequest::kOnceByModel), 2) << "each answer ends a request: ask again";
  // Unanswered, the request is repeated only after the tracker's own timeout could have answered it.
  h.timers.advance(LocalizeSkill::kRetryPeriod);
  EXPECT_EQ(h.tracker.count(TrackerRequest::kOnceByModel), 2);
  h.timers.advance(LocalizeSkill::kModelRetryPeriod);
  EXPECT_EQ(h.tracker.count(TrackerRequest::kOnceByModel), 3);
  TrackedObjectSample found = h.tracker.sample("load", true, 0.95);
  found.status = "FOUND";
  h.tracker.publish(found);
  EXPECT_EQ(h.state(), "update");
  ASSERT_TRUE(h.world.answer_update(OpResult::success("ACCEPTED")));
  EXPECT_TRUE(h.succeeded());
}

TEST_F(LocalizeTest, ByModelFailsWithTheTrackersLastCodeAtTheTimeout) {
  params_["method"] = "model";
  RunHarness h(type_, params_);
  h.run->start();
  TrackedObjectSample refused = h.tracker.sample("load", false, 0.0);
  refused.status = "AMBIGUOUS";
  refused.detail = "two poses fit within 3 %";
  h.tracker.publish(refused);
  h.timers.advance(3s);
  ASSERT_TRUE(h.failed_with("AMBIGUOUS")) << (h.result ? h.result->code : "no result");
  EXPECT_NE(h.result->message.find("two poses fit"), std::string::npos) << h.result->message;
  EXPECT_EQ(h.timers.pending(), 0u);
}

TEST_F(LocalizeTest, ByModelFailsAtOnceWhenTheObjectHasNoModel) {
  params_["method"] = "model";
  RunHarness h(type_, params_);
  h.run->start();
  TrackedObjectSample none = h.tracker.sample("load", false, 0.0);
  none.status = "NO_MODEL";
  none.detail = "'load' is no object of the cell with a STEP model (model.step)";
  h.tracker.publish(none);
  ASSERT_TRUE(h.failed_with("NO_MODEL")) << (h.result ? h.result->code : "no result");
  EXPECT_EQ(h.timers.pending(), 0u);
}

TEST_F(LocalizeTest, BadParamsFailBeforeAnythingIsCommanded) {
  for (const auto& params :
       {nlohmann::json{{"object", ""}}, nlohmann::json{{"object", "load"}, {"min_quality", 1.5}},
        nlohmann::json{{"min_quality", 0.5}}, nlohmann::json{{"object", "load"}, {"timeout_s", -1}},
        nlohmann::json{{"object", "load"}, {"method", "depth"}}}) {
    RunHarness h(type_, params);
    h.run->start();
    ASSERT_TRUE(h.failed_with("BAD_PARAMS")) << params.dump();
    EXPECT_TRUE(h.tracker.commands.empty());
  }
}

TEST_F(LocalizeTest, MissingDevicesAreDeviceUnavailable) {
  for (int which = 0; which < 2; ++which) {
    RunHarness h(type_, params_, [which](Devices& d) {
      if (which == 0)
        d.tracker = nullptr;
      else
        d.world_access = nullptr;
    });
    h.run->start();
    EXPECT_TRUE(h.failed_with("DEVICE_UNAVAILABLE")) << which;
  }
}

TEST_F(LocalizeTest, ShutdownFromEveryStateIsStoppedAtOnceAndLeavesNothingPending) {
  // detect
  {
    RunHarness h(type_, params_);
    h.run->start();
    h.run->shutdown("test");
    ASSERT_TRUE(h.stopped());
    EXPECT_EQ(h.timers.pending(), 0u);
    EXPECT_EQ(h.tracker.watches(), 0u);
  }
  // update: the world's late answer is dropped
  {
    RunHarness h(type_, params_);
    h.run->start();
    h.tracker.publish(h.tracker.sample("load", true, 0.9));
    h.run->shutdown("test");
    ASSERT_TRUE(h.stopped());
    EXPECT_FALSE(h.world.answer_update(OpResult::success())) << "the update wait was not cancelled";
    EXPECT_EQ(h.results, 1);
  }
  // every state's safe stop directly
  RunHarness h(type_, params_);
  h.run->start();
  run_steps::expect_every_safe_stop_safe(h);
}

}  // namespace
}  // namespace rigger::skill_executor
