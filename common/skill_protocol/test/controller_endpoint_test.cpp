// The controller's half of the skill protocol, its pure rule: events in order per writer.

#include "rigger/skill_protocol/controller_endpoint.hpp"

#include <gtest/gtest.h>

namespace rigger::skill_protocol {
namespace {

TEST(EventOrder, AcceptsOnlyNewerSeqsPerWriter) {
  EventOrder order;
  std::uint64_t last = 99;
  EXPECT_TRUE(order.accept(1, 1, &last));
  EXPECT_EQ(last, 0U);
  EXPECT_TRUE(order.accept(1, 5, &last));
  EXPECT_EQ(last, 1U);
  EXPECT_FALSE(order.accept(1, 5, &last)) << "duplicate";
  EXPECT_EQ(last, 5U);
  EXPECT_FALSE(order.accept(1, 3, &last)) << "out of order";
  EXPECT_EQ(last, 5U) << "a rejected seq does not move the last one";
  EXPECT_TRUE(order.accept(2, 1)) << "another writer counts on its own";
  EXPECT_FALSE(order.accept(1, 0)) << "seq 0 is never newer";
}

}  // namespace
}  // namespace rigger::skill_protocol
