// The wire boundary: every check a sample can fail before reaching the store.
#include "wire_decoding.hpp"

#include <cmath>
#include <limits>

#include <gtest/gtest.h>

#include "world_json.hpp"

namespace rigger::world {
namespace {

class UpdateDecodingTest : public ::testing::Test {
 protected:
  UpdateDecodingTest() {
    wire_.source = const_cast<char*>(source_.c_str());
    wire_.entity_id = const_cast<char*>(entity_.c_str());
    wire_.parent_frame = const_cast<char*>(parent_.c_str());
    wire_.attributes_json = const_cast<char*>(attributes_.c_str());
    wire_.seq = 3;
    wire_.has_pose = true;
    wire_.pose.pose.position = {1.0, 2.0, 3.0};
    wire_.pose.pose.orientation = {0.0, 0.0, 0.0, 1.0};
    wire_.stamp = {1700000000, 500};
  }

  std::string code_of(const Decoded<EntityUpdate>& d) {
    const auto* e = std::get_if<DecodeError>(&d);
    return e ? e->code : "OK";
  }

  std::string source_ = "vision_tracker", entity_ = "load", parent_ = "", attributes_ = "";
  rigger_world_EntityUpdate wire_{};
};

TEST_F(UpdateDecodingTest, AFullUpdateDecodesEveryGivenPart) {
  parent_ = "world";
  attributes_ = R"({"mass_kg": 40})";
  wire_.parent_frame = const_cast<char*>(parent_.c_str());
  wire_.attributes_json = const_cast<char*>(attributes_.c_str());
  wire_.has_quality = true;
  wire_.quality = 0.75;
  wire_.has_localized = true;
  wire_.localized = false;
  wire_.has_covariance = true;
  for (int i = 0; i < 36; ++i) wire_.pose.covariance[i] = (i % 7 == 0) ? 0.01 : 0.0;
  const auto d = decode_update(wire_);
  ASSERT_EQ(code_of(d), "OK");
  const auto& u = std::get<EntityUpdate>(d);
  EXPECT_EQ(u.entity_id, "load");
  EXPECT_EQ(u.source, "vision_tracker");
  EXPECT_EQ(u.parent, std::optional<std::string>("world"));
  ASSERT_TRUE(u.pose);
  EXPECT_TRUE(u.pose->position_m.isApprox(Eigen::Vector3d(1, 2, 3)));
  EXPECT_EQ(u.quality, std::optional<double>(0.75));
  EXPECT_EQ(u.localized, std::optional<bool>(false));
  ASSERT_TRUE(u.covariance);
  EXPECT_DOUBLE_EQ((*u.covariance)(1, 1), 0.01);
  EXPECT_DOUBLE_EQ((*u.covariance)(0, 1), 0.0);
  EXPECT_EQ((*u.attributes_patch)["mass_kg"], 40);
  EXPECT_EQ(to_unix_ns(u.stamp), 1700000000LL * 1000000000LL + 500);
}

TEST_F(UpdateDecodingTest, AbsentPartsStayAbsent) {
  wire_.has_pose = false;
  wire_.has_localized = true;
  wire_.localized = true;
  const auto d = decode_update(wire_);
  ASSERT_EQ(code_of(d), "OK");
  const auto& u = std::get<EntityUpdate>(d);
  EXPECT_FALSE(u.pose);
  EXPECT_FALSE(u.parent);
  EXPECT_FALSE(u.quality);
  EXPECT_FALSE(u.covariance);
  EXPECT_FALSE(u.attributes_patch);
}

TEST_F(UpdateDecodingTest, TheQuaternionIsKeptAsSentForTheStoreToJudge) {
  wire_.pose.pose.orientation = {0.0, 0.0, 0.0, 2.0};
  const auto d = decode_update(wire_);
  ASSERT_EQ(code_of(d), "OK");
  EXPECT_DOUBLE_EQ(std::get<EntityUpdate>(d).pose->orientation.w(), 2.0);
}

TEST_F(UpdateDecodingTest, NullStringsAndBadIdsAreRefused) {
  wire_.entity_id = nullptr;
  EXPECT_EQ(code_of(decode_update(wire_)), "BAD_ID");
  std::string bad = "lo ad";
  wire_.entity_id = const_cast<char*>(bad.c_str());
  EXPECT_EQ(code_of(decode_update(wire_)), "BAD_ID");
  wire_.entity_id = const_cast<char*>(entity_.c_str());
  wire_.source = nullptr;
  EXPECT_EQ(code_of(decode_update(wire_)), "MISSING_SOURCE");
  wire_.source = const_cast<char*>(source_.c_str());
  std::string bad_parent = "world/x";
  wire_.parent_frame = const_cast<char*>(bad_parent.c_str());
  EXPECT_EQ(code_of(decode_update(wire_)), "BAD_ID");
}

TEST_F(UpdateDecodingTest, NanosecondsBeyondOneSecondAreABadStamp) {
  wire_.stamp.nanosec = 1000000000u;
  EXPECT_EQ(code_of(decode_update(wire_)), "BAD_STAMP");
  wire_.stamp.nanosec = 999999999u;
  EXPECT_EQ(code_of(decode_update(wire_)), "OK");
}

TEST_F(UpdateDecodingTest, NonFiniteNumbersAreRefusedWhereverTheyAre) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  auto expect_refused = [&](auto mutate, const char* what) {
    rigger_world_EntityUpdate saved = wire_;
    mutate(wire_);
    EXPECT_EQ(code_of(decode_update(wire_)), "NOT_FINITE") << what;
    wire_ = saved;
  };
  expect_refused([&](auto& w) { w.pose.pose.position.y = nan; }, "position");
  expect_refused([&](auto& w) { w.pose.pose.orientation.z = inf; }, "orientation");
  expect_refused([&](auto& w) { w.has_covariance = true; w.pose.covariance[35] = nan; }, "covariance");
  expect_refused([&](auto& w) { w.has_quality = true; w.quality = nan; }, "quality");
  // Not given: not looked at.
  wire_.has_pose = false;
  wire_.has_localized = true;
  wire_.pose.pose.position.x = nan;
  EXPECT_EQ(code_of(decode_update(wire_)), "OK");
}

TEST_F(UpdateDecodingTest, AttributesMustBeABoundedJsonObject) {
  const std::vector<std::string> texts = {"[1,2]", "{not json", "42", std::string(20, '[') + std::string(20, ']')};
  for (const std::string& text : texts) {
    attributes_ = text;
    wire_.attributes_json = const_cast<char*>(attributes_.c_str());
    EXPECT_EQ(code_of(decode_update(wire_)), "BAD_ATTRIBUTES") << text;
  }
  attributes_ = "{\"a\":\"" + std::string(kMaxAttributesJsonBytes, 'x') + "\"}";
  wire_.attributes_json = const_cast<char*>(attributes_.c_str());
  EXPECT_EQ(code_of(decode_update(wire_)), "BAD_ATTRIBUTES");
  // Deep nesting is refused while parsing, not after building a deep tree.
  attributes_ = std::string(100000, '[');
  wire_.attributes_json = const_cast<char*>(attributes_.c_str());
  EXPECT_EQ(code_of(decode_update(wire_)), "BAD_ATTRIBUTES");
}

TEST_F(UpdateDecodingTest, ErrorMessagesQuoteOnlyAShortPrintableId) {
  std::string huge(10000, '\x01');
  wire_.entity_id = const_cast<char*>(huge.c_str());
  const auto d = decode_update(wire_);
  ASSERT_EQ(code_of(d), "BAD_ID");
  EXPECT_LT(std::get<DecodeError>(d).message.size(), 200u);
  EXPECT_EQ(std::get<DecodeError>(d).message.find('\x01'), std::string::npos);
}

class QueryDecodingTest : public ::testing::Test {
 protected:
  QueryDecodingTest() {
    wire_.client_id = const_cast<char*>(client_.c_str());
    wire_.entity_id = const_cast<char*>(entity_.c_str());
    wire_.frame_id = const_cast<char*>(frame_.c_str());
    wire_.feature_id = const_cast<char*>(feature_.c_str());
    wire_.request_id = 9;
    wire_.kind = rigger_world_QUERY_POSE;
  }
  std::string code_of(const Decoded<WorldQuery>& d) {
    const auto* e = std::get_if<DecodeError>(&d);
    return e ? e->code : "OK";
  }
  std::string client_ = "ctl", entity_ = "load", frame_ = "world", feature_ = "";
  rigger_world_WorldQuery wire_{};
};

TEST_F(QueryDecodingTest, PoseQueryDecodes) {
  const auto d = decode_query(wire_);
  ASSERT_EQ(code_of(d), "OK");
  const auto& q = std::get<WorldQuery>(d);
  EXPECT_EQ(q.kind, QueryKind::kPose);
  EXPECT_EQ(q.client_id, "ctl");
  EXPECT_EQ(q.request_id, 9u);
  EXPECT_EQ(q.frame_id, "world");
  EXPECT_FALSE(q.max_age);
}

TEST_F(QueryDecodingTest, UnknownKindIsABadQuery) {
  wire_.kind = static_cast<rigger_world_QueryKind>(17);
  EXPECT_EQ(code_of(decode_query(wire_)), "BAD_QUERY");
  wire_.kind = static_cast<rigger_world_QueryKind>(-1);
  EXPECT_EQ(code_of(decode_query(wire_)), "BAD_QUERY");
}

TEST_F(QueryDecodingTest, IdsAreCheckedWhereTheKindNeedsThem) {
  wire_.frame_id = nullptr;
  EXPECT_EQ(code_of(decode_query(wire_)), "BAD_ID");  // a pose needs a frame
  wire_.kind = rigger_world_QUERY_FEATURES;
  EXPECT_EQ(code_of(decode_query(wire_)), "OK");  // features do not
  wire_.entity_id = nullptr;
  EXPECT_EQ(code_of(decode_query(wire_)), "BAD_ID");
  wire_.kind = rigger_world_QUERY_LIST;
  EXPECT_EQ(code_of(decode_query(wire_)), "OK");  // a list needs no entity
  wire_.kind = rigger_world_QUERY_POSE;
  wire_.entity_id = const_cast<char*>(entity_.c_str());
  wire_.frame_id = const_cast<char*>(frame_.c_str());
  std::string bad_feature = "h 3";
  wire_.feature_id = const_cast<char*>(bad_feature.c_str());
  EXPECT_EQ(code_of(decode_query(wire_)), "BAD_ID");
}

TEST_F(QueryDecodingTest, MaxAgeMustBeFiniteAndNonPositiveMeansAnyAge) {
  wire_.kind = rigger_world_QUERY_IS_LOCALIZED;
  wire_.max_age_s = std::nan("");
  EXPECT_EQ(code_of(decode_query(wire_)), "BAD_QUERY");
  wire_.max_age_s = -1.0;
  EXPECT_FALSE(std::get<WorldQuery>(decode_query(wire_)).max_age);
  wire_.max_age_s = 1e300;
  EXPECT_FALSE(std::get<WorldQuery>(decode_query(wire_)).max_age);
  wire_.max_age_s = 0.5;
  EXPECT_EQ(std::get<WorldQuery>(decode_query(wire_)).max_age, std::chrono::milliseconds(500));
}

}  // namespace
}  // namespace rigger::world

namespace rigger::world {
namespace {

TEST(TrackedPoseDecodingTest, ATrackedPoseLocalizesInItsHeaderFrame) {
  std::string object = "load", frame = "world";
  rigger_vision_TrackedPose w{};
  w.object_id = object.data();
  w.header.frame_id = frame.data();
  w.header.stamp = {1700000000, 0};
  w.tracked = true;
  w.quality = 0.8;
  w.pose.pose.orientation.w = 1.0;
  w.pose.pose.position.x = 3.5;
  auto d = decode_tracked_pose(w);
  ASSERT_TRUE(std::holds_alternative<EntityUpdate>(d));
  auto u = std::get<EntityUpdate>(d);
  EXPECT_EQ(u.source, kTrackerSource);
  EXPECT_EQ(u.parent, std::optional<std::string>("world"));
  EXPECT_EQ(u.localized, std::optional<bool>(true));
  EXPECT_EQ(u.quality, std::optional<double>(0.8));
  EXPECT_FALSE(u.covariance);  // all zeros: unknown
  w.pose.covariance[0] = -1.0;
  w.pose.covariance[7] = 0.5;
  EXPECT_FALSE(std::get<EntityUpdate>(decode_tracked_pose(w)).covariance);  // ROS "unknown"
  w.pose.covariance[0] = 0.5;
  EXPECT_TRUE(std::get<EntityUpdate>(decode_tracked_pose(w)).covariance);
}

TEST(TrackedPoseDecodingTest, ALostObjectOnlyBecomesUnlocalized) {
  std::string object = "load";
  rigger_vision_TrackedPose w{};
  w.object_id = object.data();
  w.header.stamp = {1700000000, 0};
  w.tracked = false;
  w.pose.pose.position.x = std::nan("");  // ignored when lost
  auto d = decode_tracked_pose(w);
  ASSERT_TRUE(std::holds_alternative<EntityUpdate>(d));
  const auto& u = std::get<EntityUpdate>(d);
  EXPECT_FALSE(u.pose);
  EXPECT_FALSE(u.parent);
  EXPECT_EQ(u.localized, std::optional<bool>(false));
  w.object_id = nullptr;
  EXPECT_TRUE(std::holds_alternative<DecodeError>(decode_tracked_pose(w)));
}

}  // namespace
}  // namespace rigger::world
