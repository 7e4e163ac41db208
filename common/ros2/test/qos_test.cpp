#include "rigger/ros2/qos.hpp"

#include <gtest/gtest.h>

namespace rigger::ros2 {
namespace {

struct Policies {
  dds_reliability_kind_t reliability;
  dds_history_kind_t history;
  int32_t depth;
  dds_durability_kind_t durability;
};

// Expects `q` to hold exactly the policies in `want`.
void expect_policies(const dds::Qos& q, const Policies& want) {
  Policies got{};
  ASSERT_TRUE(dds_qget_reliability(q.get(), &got.reliability, nullptr));
  ASSERT_TRUE(dds_qget_history(q.get(), &got.history, &got.depth));
  ASSERT_TRUE(dds_qget_durability(q.get(), &got.durability));
  EXPECT_EQ(got.reliability, want.reliability);
  EXPECT_EQ(got.history, want.history);
  EXPECT_EQ(got.depth, want.depth);
  EXPECT_EQ(got.durability, want.durability);
}

TEST(Ros2Qos, SensorDataIsBestEffortKeepLast5Volatile) {
  expect_policies(qos::sensor_data(), {DDS_RELIABILITY_BEST_EFFORT, DDS_HISTORY_KEEP_LAST, 5, DDS_DURABILITY_VOLATILE});
}

TEST(Ros2Qos, ReliableDefaultIsReliableKeepLast10Volatile) {
  expect_policies(qos::reliable_default(),
                  {DDS_RELIABILITY_RELIABLE, DDS_HISTORY_KEEP_LAST, 10, DDS_DURABILITY_VOLATILE});
}

TEST(Ros2Qos, SystemDefaultIsReliableKeepLast1Volatile) {
  expect_policies(qos::system_default(), {DDS_RELIABILITY_RELIABLE, DDS_HISTORY_KEEP_LAST, 1, DDS_DURABILITY_VOLATILE});
}

}  // namespace
}  // namespace rigger::ros2
