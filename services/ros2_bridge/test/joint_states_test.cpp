#include "joint_states.hpp"

#include <cmath>
#include <limits>
#include <stdexcept>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

namespace rigger::ros2_bridge {
namespace {

using ::testing::HasSubstr;

const JointMap& arm() {
  static const JointMap map({"shoulder_pan", "shoulder_lift", "elbow"}, {"finger"});
  return map;
}

struct Message {
  std::vector<std::string_view> names;
  std::vector<double> positions;
  std::vector<double> velocities;
  ChainJoints map() const {
    return arm().map(names, positions.data(), positions.size(), velocities.data(), velocities.size());
  }
};

// As UR's driver publishes them: not in chain order, with a joint that is not the arm's.
TEST(JointMap, PutsTheDriversOrderIntoChainOrderByName) {
  const ChainJoints j =
      Message{{"elbow", "finger", "shoulder_lift", "shoulder_pan"}, {3.0, 9.0, 2.0, 1.0}, {0.3, 9.0, 0.2, 0.1}}.map();
  ASSERT_EQ(j.verdict, JointStateVerdict::kOk) << j.detail;
  EXPECT_EQ(j.position_rad, Eigen::Vector3d(1.0, 2.0, 3.0));
  EXPECT_EQ(j.velocity_radps, Eigen::Vector3d(0.1, 0.2, 0.3));
}

TEST(JointMap, RefusesWhatItCannotMapSayingWhich) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  const auto refused = [](const Message& m, JointStateVerdict verdict, const std::string& detail) {
    const ChainJoints j = m.map();
    EXPECT_EQ(j.verdict, verdict) << joint_state_verdict_name(j.verdict) << ": " << j.detail;
    EXPECT_THAT(j.detail, HasSubstr(detail));
  };
  refused({{"shoulder_pan", "shoulder_lift", "elbow", "wrist_1"}, {1, 2, 3, 4}, {0, 0, 0, 0}},
          JointStateVerdict::kUnknownJoint, "'wrist_1' is neither one of the arm's joints nor ignored");
  refused({{"shoulder_pan", "elbow"}, {1, 3}, {0, 0}}, JointStateVerdict::kMissingJoint, "'shoulder_lift' is missing");
  refused({{"shoulder_pan", "shoulder_lift", "elbow", "elbow"}, {1, 2, 3, 3}, {0, 0, 0, 0}},
          JointStateVerdict::kDuplicateJoint, "'elbow' twice");
  refused({{"shoulder_pan", "shoulder_lift", "elbow", "finger", "finger"}, {1, 2, 3, 0, 0}, {0, 0, 0, 0, 0}},
          JointStateVerdict::kDuplicateJoint, "'finger' twice");
  // joint_state_broadcaster writes NaN for an interface the hardware does not have.
  refused({{"shoulder_pan", "shoulder_lift", "elbow"}, {1, 2, 3}, {0, nan, 0}}, JointStateVerdict::kNotFinite,
          "'shoulder_lift' position=2.000000 velocity=nan");
  refused({{"shoulder_pan", "shoulder_lift", "elbow"}, {1, 2, inf}, {0, 0, 0}}, JointStateVerdict::kNotFinite,
          "'elbow' position=inf");
  // Velocities are needed for the tool twist: a driver that gives none is refused, not read as at rest.
  refused({{"shoulder_pan", "shoulder_lift", "elbow"}, {1, 2, 3}, {}}, JointStateVerdict::kLayout,
          "names=3 positions=3 velocities=0");
  refused({{"shoulder_pan", "shoulder_lift", "elbow"}, {1, 2}, {0, 0, 0}}, JointStateVerdict::kLayout, "positions=2");
  refused({{}, {}, {}}, JointStateVerdict::kMissingJoint, "'shoulder_pan' is missing");
  // An ignored joint's values are not looked at.
  EXPECT_EQ(
      (Message{{"shoulder_pan", "shoulder_lift", "elbow", "finger"}, {1, 2, 3, nan}, {0, 0, 0, nan}}.map().verdict),
      JointStateVerdict::kOk);
}

TEST(JointMap, RefusesABadListOfNames) {
  EXPECT_THROW(JointMap({"a", "b", "a"}, {}), std::invalid_argument);
  EXPECT_THROW(JointMap({"a", ""}, {}), std::invalid_argument);
  EXPECT_THROW(JointMap({"a"}, {"a"}), std::invalid_argument);
}

}  // namespace
}  // namespace rigger::ros2_bridge
