// CellFollower on a real DDS domain of its own: a revision written on rigger/world/cell reaches the reader's
// callback (also when written before the follower existed), the configured file's own document is taken
// without a callback, refusals are kept and reported, repeats are ignored.
#include "rigger/cell_follower/cell_follower.hpp"

#include <fstream>
#include <iterator>
#include <vector>

#include <gtest/gtest.h>

#include "rigger/protocol/world.hpp"
#include "rigger/testing/domain.hpp"

namespace rigger::cell_follower {
namespace {

using namespace std::chrono_literals;
namespace fs = std::filesystem;

const fs::path kShippedCell = fs::path(RIGGER_SOURCE_DIR) / "deploy/cell/simulated_cell.json";

std::string shipped_text() {
  std::ifstream in(kShippedCell, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

/// The shipped cell with its description changed: another document, equally valid.
world_protocol::CellRevision edited(std::uint64_t number, const std::string& description) {
  nlohmann::json cell = nlohmann::json::parse(shipped_text());
  cell["description"] = description;
  world_protocol::CellRevision r;
  r.cell_revision = number;
  r.previous_revision = number - 1;
  r.cell_json = cell.dump(2);
  r.sha256 = "sha-" + std::to_string(number);
  r.changes_json = R"({"changed":[]})";
  return r;
}

class CellFollowerTest : public ::testing::Test {
 protected:
  dds_return_t publish(const world_protocol::CellRevision& r) {
    rigger_world_CellRevision wire{};
    world_protocol::to_wire(r, wire);
    return writer_.write(wire);
  }
  std::unique_ptr<CellFollower> follow(std::function<Outcome(const FollowedRevision&)> on_revision) {
    return std::make_unique<CellFollower>(participant_, loop_, null_logger(), kShippedCell, std::move(on_revision));
  }

  testing::DomainLease domain_;
  dds::Participant participant_{domain_.id()};
  dds::EventLoop loop_{participant_};
  dds::Writer<rigger_world_CellRevision> writer_{participant_, protocol::world::kCell};
};

TEST_F(CellFollowerTest, ARevisionWrittenBeforeTheFollowerStartedReachesItsCallback) {
  ASSERT_EQ(publish(edited(3, "three")), DDS_RETCODE_OK);
  std::vector<std::uint64_t> seen;
  std::string description;
  auto follower = follow([&](const FollowedRevision& r) {
    seen.push_back(r.revision);
    description = r.cell.description;
    return Outcome::take();
  });
  ASSERT_TRUE(loop_.run_until([&] { return follower->revision() == 3; }, 5s));
  EXPECT_EQ(seen, std::vector<std::uint64_t>{3});
  EXPECT_EQ(description, "three");
  ASSERT_EQ(publish(edited(4, "four")), DDS_RETCODE_OK);
  ASSERT_TRUE(loop_.run_until([&] { return follower->revision() == 4; }, 5s));
  EXPECT_EQ(seen, (std::vector<std::uint64_t>{3, 4}));
}

TEST_F(CellFollowerTest, TheConfiguredFilesOwnDocumentIsTakenWithoutACallback) {
  int calls = 0;
  auto follower = follow([&](const FollowedRevision&) {
    ++calls;
    return Outcome::take();
  });
  world_protocol::CellRevision first;
  first.cell_revision = 1;
  first.cell_json = shipped_text();
  first.sha256 = "sha-1";
  follower->offer(first);
  EXPECT_EQ(follower->revision(), 1U);
  EXPECT_EQ(calls, 0);
}

TEST_F(CellFollowerTest, ARefusalKeepsTheRunningRevisionAndARepeatIsIgnored) {
  int calls = 0;
  auto follower = follow([&](const FollowedRevision& r) {
    ++calls;
    return r.revision == 6 ? Outcome::refuse("the physics cannot hold it") : Outcome::take();
  });
  follower->offer(edited(5, "five"));
  ASSERT_EQ(follower->revision(), 5U);
  follower->offer(edited(6, "six"));
  EXPECT_EQ(follower->revision(), 5U);
  EXPECT_EQ(follower->last_refusal(), "cell revision 6: the physics cannot hold it");
  follower->offer(edited(6, "six"));
  EXPECT_EQ(calls, 2);
  // A revision the follower cannot even read never reaches the callback.
  world_protocol::CellRevision broken = edited(7, "seven");
  broken.cell_json = "{";
  follower->offer(broken);
  EXPECT_EQ(calls, 2);
  EXPECT_EQ(follower->revision(), 5U);
  EXPECT_NE(follower->last_refusal().find("cell revision 7: " + kShippedCell.string()), std::string::npos)
      << follower->last_refusal();
  follower->offer(edited(8, "eight"));
  EXPECT_EQ(follower->revision(), 8U);
  EXPECT_TRUE(follower->last_refusal().empty());
}

}  // namespace
}  // namespace rigger::cell_follower
