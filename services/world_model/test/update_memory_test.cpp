#include "update_memory.hpp"

#include <gtest/gtest.h>

namespace rigger::world {
namespace {

world_protocol::UpdateResult result(const std::string& source, std::uint64_t seq, std::uint64_t revision) {
  return world_protocol::UpdateResult{source, seq, "load", true, "ACCEPTED", "", revision};
}

TEST(UpdateMemory, AnswersARepeatBySourceAndSeq) {
  UpdateMemory memory;
  EXPECT_EQ(memory.find("skills", 1), nullptr);
  memory.remember(result("skills", 1, 7));
  memory.remember(result("tracker", 1, 8));
  const world_protocol::UpdateResult* known = memory.find("skills", 1);
  ASSERT_NE(known, nullptr);
  EXPECT_EQ(known->revision, 7u);
  EXPECT_EQ(memory.find("tracker", 1)->revision, 8u);
  EXPECT_EQ(memory.find("skills", 2), nullptr);
}

TEST(UpdateMemory, ForgetsTheOldestBeyondItsCapacity) {
  UpdateMemory memory(2);
  memory.remember(result("a", 1, 1));
  memory.remember(result("a", 2, 2));
  memory.remember(result("a", 2, 3));  // the same update again: replaced, not counted twice
  EXPECT_EQ(memory.size(), 2u);
  EXPECT_EQ(memory.find("a", 2)->revision, 3u);
  memory.remember(result("a", 3, 4));
  EXPECT_EQ(memory.size(), 2u);
  EXPECT_EQ(memory.find("a", 1), nullptr);
  EXPECT_NE(memory.find("a", 2), nullptr);
  EXPECT_NE(memory.find("a", 3), nullptr);
}

}  // namespace
}  // namespace rigger::world
