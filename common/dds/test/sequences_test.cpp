#include "rigger/dds/sequences.hpp"

#include <gtest/gtest.h>

#include <cstdint>
#include <vector>

#include <rigger/idl/types.hpp>

namespace rigger::dds {
namespace {

TEST(Sequences, ElementsViewsWhatWireBufferBorrowed) {
  std::vector<std::uint8_t> bytes{1, 2, 3};
  rigger_cad_CadReply reply{};
  wire_buffer(reply.data, bytes.data(), bytes.size());
  EXPECT_FALSE(reply.data._release);
  const auto view = elements(reply.data);
  ASSERT_EQ(view.size(), 3U);
  EXPECT_EQ(view.data(), bytes.data());
  EXPECT_EQ(view[2], 3);
  EXPECT_EQ(std::vector<std::uint8_t>(view.begin(), view.end()), bytes);
}

TEST(Sequences, NullBufferReadsAsEmptyWhateverItsLength) {
  rigger_cad_CadReply reply{};
  reply.data._length = 5;  // a malformed sample: no buffer behind the length
  EXPECT_TRUE(elements(reply.data).empty());
  int visited = 0;
  for (auto b : elements(reply.data)) visited += b;
  EXPECT_EQ(visited, 0);
}

TEST(Sequences, AllocSequenceOwnsItsElementsUntilTheSampleIsFreed) {
  rigger_robot_MotionCommand command{};
  double* goal = alloc_sequence(command.joint_goal, 7);
  for (int i = 0; i < 7; ++i) goal[i] = 0.5 * i;
  EXPECT_TRUE(command.joint_goal._release);
  ASSERT_EQ(elements(command.joint_goal).size(), 7U);
  EXPECT_DOUBLE_EQ(elements(command.joint_goal)[6], 3.0);
  dds_sample_free(&command, &rigger_robot_MotionCommand_desc, DDS_FREE_CONTENTS);  // frees the elements
  EXPECT_EQ(alloc_sequence(command.joint_goal, 0), nullptr);
}

}  // namespace
}  // namespace rigger::dds
