#include "tracking_schedule.hpp"

#include <gtest/gtest.h>

namespace rigger::vision {
namespace {

using namespace std::chrono_literals;

const Stamp kCommandStamp{std::chrono::seconds(1000)};
const SteadyTime kNow{std::chrono::seconds(50)};

class TrackingScheduleTest : public ::testing::Test {
 protected:
  TrackingSchedule schedule_{{"load", "target"}, 0.5};
};

TEST_F(TrackingScheduleTest, StartsIdle) {
  EXPECT_FALSE(schedule_.any_active());
  EXPECT_FALSE(schedule_.on_track("load", kCommandStamp + 1s, true, 0.9));
}

TEST_F(TrackingScheduleTest, TrackOnceEndsAtTheFirstFreshGoodPoseOfItsObject) {
  ASSERT_TRUE(schedule_.track_once("load", kCommandStamp, kNow + 2s));
  EXPECT_TRUE(schedule_.any_active());
  EXPECT_TRUE(schedule_.once_pending("load"));
  EXPECT_FALSE(schedule_.once_pending("target"));
  EXPECT_FALSE(schedule_.on_track("target", kCommandStamp + 1ms, true, 0.9)) << "another object";
  EXPECT_FALSE(schedule_.on_track("load", kCommandStamp, true, 0.9)) << "an image from before the command";
  EXPECT_FALSE(schedule_.on_track("load", kCommandStamp + 1ms, false, 0.0)) << "not detected";
  EXPECT_FALSE(schedule_.on_track("load", kCommandStamp + 2ms, true, 0.49)) << "below the minimum quality";
  EXPECT_TRUE(schedule_.once_pending("load"));
  EXPECT_TRUE(schedule_.on_track("load", kCommandStamp + 3ms, true, 0.5));
  EXPECT_FALSE(schedule_.once_pending("load"));
  EXPECT_FALSE(schedule_.any_active()) << "back to idle";
  EXPECT_FALSE(schedule_.on_track("load", kCommandStamp + 4ms, true, 0.9));
}

TEST_F(TrackingScheduleTest, TrackOnceOnAContinuousObjectReturnsToContinuous) {
  ASSERT_TRUE(schedule_.track_continuous("target"));
  ASSERT_TRUE(schedule_.track_once("target", kCommandStamp, kNow + 2s));
  EXPECT_TRUE(schedule_.on_track("target", kCommandStamp, false, 0.0)) << "continuous: every track is published";
  EXPECT_TRUE(schedule_.once_pending("target"));
  EXPECT_TRUE(schedule_.on_track("target", kCommandStamp + 1ms, true, 0.8));
  EXPECT_FALSE(schedule_.once_pending("target"));
  EXPECT_TRUE(schedule_.continuous("target"));
  EXPECT_TRUE(schedule_.on_track("target", kCommandStamp + 2ms, true, 0.8));
}

TEST_F(TrackingScheduleTest, ExpiredTrackOnceIsReportedUnlessTheObjectIsContinuous) {
  ASSERT_TRUE(schedule_.track_once("", kCommandStamp, kNow + 2s));
  ASSERT_TRUE(schedule_.track_continuous("target"));
  EXPECT_TRUE(schedule_.expire(kNow + 1s).empty());
  EXPECT_EQ(schedule_.expire(kNow + 2s), std::vector<std::string>{"load"});
  EXPECT_FALSE(schedule_.once_pending("load"));
  EXPECT_FALSE(schedule_.once_pending("target"));
  EXPECT_TRUE(schedule_.continuous("target"));
  EXPECT_TRUE(schedule_.expire(kNow + 3s).empty()) << "expired once only";
}

TEST_F(TrackingScheduleTest, ANewTrackOnceReplacesThePendingOne) {
  ASSERT_TRUE(schedule_.track_once("load", kCommandStamp, kNow + 2s));
  ASSERT_TRUE(schedule_.track_once("load", kCommandStamp + 1s, kNow + 5s));
  EXPECT_TRUE(schedule_.expire(kNow + 3s).empty());
  EXPECT_FALSE(schedule_.on_track("load", kCommandStamp + 500ms, true, 0.9)) << "older than the newer command";
  EXPECT_TRUE(schedule_.on_track("load", kCommandStamp + 1001ms, true, 0.9));
}

TEST_F(TrackingScheduleTest, ContinuousAndStopArePerObjectOrForAll) {
  ASSERT_TRUE(schedule_.track_continuous(""));
  EXPECT_TRUE(schedule_.continuous("load"));
  EXPECT_TRUE(schedule_.continuous("target"));
  ASSERT_TRUE(schedule_.track_once("load", kCommandStamp, kNow + 2s));
  ASSERT_TRUE(schedule_.stop("load"));
  EXPECT_FALSE(schedule_.continuous("load"));
  EXPECT_FALSE(schedule_.once_pending("load")) << "STOP drops a pending TRACK_ONCE";
  EXPECT_TRUE(schedule_.expire(kNow + 2s).empty()) << "and nothing is reported for it";
  EXPECT_FALSE(schedule_.on_track("load", kCommandStamp + 1s, true, 0.9));
  EXPECT_TRUE(schedule_.on_track("target", kCommandStamp + 1s, false, 0.0));
  ASSERT_TRUE(schedule_.stop(""));
  EXPECT_FALSE(schedule_.any_active());
}

TEST_F(TrackingScheduleTest, UnknownObjectsChangeNothing) {
  EXPECT_FALSE(schedule_.track_once("crane", kCommandStamp, kNow + 2s));
  EXPECT_FALSE(schedule_.track_continuous("crane"));
  EXPECT_FALSE(schedule_.stop("crane"));
  EXPECT_FALSE(schedule_.any_active());
  EXPECT_FALSE(schedule_.on_track("crane", kCommandStamp + 1s, true, 0.9));
}

TEST_F(TrackingScheduleTest, ANewCellKeepsTheStateOfKeptObjectsAndDropsRemovedOnes) {
  ASSERT_TRUE(schedule_.track_continuous("load"));
  ASSERT_TRUE(schedule_.track_once("target", kCommandStamp, kNow + 2s));
  const std::vector<std::string> dropped = schedule_.set_objects({"load", "bracket"});
  EXPECT_EQ(dropped, std::vector<std::string>{"target"}) << "its pending TRACK_ONCE ends unanswered";
  EXPECT_TRUE(schedule_.continuous("load"));
  EXPECT_FALSE(schedule_.continuous("bracket")) << "a new object starts idle";
  EXPECT_FALSE(schedule_.once_pending("target"));
  EXPECT_FALSE(schedule_.track_continuous("target")) << "a removed object is unknown";
  EXPECT_TRUE(schedule_.track_continuous("bracket"));
}

}  // namespace
}  // namespace rigger::vision
