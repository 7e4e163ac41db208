// The console's logic without DDS or HTTP: users and tokens, the numbered event log a reconnecting
// browser resumes from, and the state snapshot's consistency with that log.
#include <filesystem>
#include <fstream>
#include <thread>

#include <gtest/gtest.h>

#include "auth.hpp"
#include "console_state.hpp"
#include "event_log.hpp"
#include "rigger/base/config.hpp"

namespace rigger::console {
namespace {

using namespace std::chrono_literals;
using nlohmann::json;

TEST(ConsoleAuth, Sha256MatchesTheStandardVector) {
  EXPECT_EQ(sha256_hex("abc"), "ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad");
}

TEST(ConsoleAuth, MadeUsersAuthenticateByTokenAndTheFileHoldsNoToken) {
  const std::string path = ::testing::TempDir() + "/console-users-" + std::to_string(::getpid()) + "/users.json";
  const auto created = make_users(path, {{"ada", Role::kProgrammer}, {"vic", Role::kViewer}});
  ASSERT_EQ(created.size(), 2U);
  std::ifstream in(path);
  const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  EXPECT_EQ(text.find(created[0].token), std::string::npos) << "the token itself must not be stored";
  EXPECT_EQ(std::filesystem::status(path).permissions() & std::filesystem::perms::others_read,
            std::filesystem::perms::none);
  const Users users = Users::load(path);
  const auto ada = users.authenticate(created[0].token);
  ASSERT_TRUE(ada);
  EXPECT_EQ(ada->name, "ada");
  EXPECT_EQ(ada->role, Role::kProgrammer);
  EXPECT_EQ(users.authenticate(created[1].token)->role, Role::kViewer);
  EXPECT_FALSE(users.authenticate(created[0].token + "x"));
  EXPECT_FALSE(users.authenticate(""));
  std::filesystem::remove_all(std::filesystem::path(path).parent_path());
}

TEST(ConsoleAuth, BadUsersFilesSayWhereAndWhat) {
  try {
    Users::parse(R"({"users": [{"name": "a", "role": "admin", "token_sha256": ""}]})", "u.json");
    FAIL() << "an unknown role must be refused";
  } catch (const ConfigError& e) {
    EXPECT_EQ(e.pointer(), "/users/0/role");
  }
  EXPECT_THROW(Users::parse(R"({"users": [{"name": "a", "role": "viewer", "token_sha256": "00"}]})", "u.json"), ConfigError);
  EXPECT_THROW(Users::parse("[[[[", "u.json"), ConfigError);
  EXPECT_THROW(Users::load("/nonexistent/users.json"), ConfigError);
}

TEST(ConsoleEventLog, ResumesAfterAnIdAndResetsForAnotherRunOrADroppedRange) {
  EventLog log(3, "77");
  for (int i = 1; i <= 5; ++i) log.append("node", "{\"i\":" + std::to_string(i) + "}");
  ASSERT_EQ(log.parse_id("77:3"), 3U);
  EXPECT_FALSE(log.parse_id("76:3")) << "an id of an earlier run";
  EXPECT_FALSE(log.parse_id("77:9")) << "an id from the future";
  EXPECT_FALSE(log.parse_id("77:x"));
  const auto b = log.wait_after(3, 100, 0ms);
  ASSERT_FALSE(b.reset);
  ASSERT_EQ(b.events.size(), 2U);
  EXPECT_EQ(b.events[0].seq, 4U);
  EXPECT_EQ(b.events[1].data, "{\"i\":5}");
  EXPECT_EQ(b.last_seq, 5U);
  const auto dropped = log.wait_after(1, 100, 0ms);  // 2 was dropped (capacity 3 keeps 3..5)
  EXPECT_TRUE(dropped.reset);
  EXPECT_EQ(dropped.last_seq, 5U);
  EXPECT_EQ(log.id_of(5), "77:5");
}

TEST(ConsoleEventLog, AWaiterWakesOnAppend) {
  EventLog log(10, "1");
  std::thread writer([&] {
    std::this_thread::sleep_for(20ms);  // the waiter below must already be waiting: that is the point
    log.append("task", "{}");
  });
  const auto b = log.wait_after(0, 10, 10s);
  writer.join();
  ASSERT_EQ(b.events.size(), 1U);
  EXPECT_EQ(b.events[0].type, "task");
}

TEST(ConsoleState, SnapshotSeqIsItsLastEventAndInactivePromptsLeave) {
  EventLog log(100, "5");
  ConsoleState state(log);
  state.update_task({{"task_id", "t"}, {"state", "RUNNING"}});
  state.update_node({{"task_id", "t"}, {"node_id", "root"}, {"state", "RUNNING"}});
  state.update_node({{"task_id", "t"}, {"node_id", "root"}, {"state", "SUCCESS"}});
  state.update_prompt({{"prompt_id", "p"}, {"active", true}, {"options", {"done"}}});
  auto snap = state.snapshot();
  EXPECT_EQ(snap["seq"], 4U);
  EXPECT_EQ(snap["id"], "5:4");
  ASSERT_EQ(snap["nodes"]["t"].size(), 1U);
  EXPECT_EQ(snap["nodes"]["t"][0]["state"], "SUCCESS");
  EXPECT_FALSE(state.prompt("p").is_null());
  state.update_prompt({{"prompt_id", "p"}, {"active", false}});
  EXPECT_TRUE(state.prompt("p").is_null());
  EXPECT_TRUE(state.snapshot()["prompts"].empty());
  EXPECT_EQ(state.snapshot("other")["nodes"].size(), 0U);
}

TEST(ConsoleState, CellChangesAreEventsAndMergeIntoTheSnapshot) {
  EventLog log(10, "1");
  ConsoleState state(log);
  state.update_cell({{"t", 1.0}, {"objects", {{"a", {{"position_m", {1, 0, 0}}}}, {"b", {{"position_m", {2, 0, 0}}}}}}});
  state.update_cell({{"t", 2.0}, {"objects", {{"a", {{"position_m", {1.5, 0, 0}}}}}}, {"tool", {0, 0, 1}}});
  const auto snap = state.snapshot();
  EXPECT_EQ(snap["seq"], 2U);
  EXPECT_EQ(snap["cell"]["objects"]["a"]["position_m"][0], 1.5);
  EXPECT_EQ(snap["cell"]["objects"]["b"]["position_m"][0], 2);
  EXPECT_EQ(snap["cell"]["tool"][2], 1);
  const auto batch = log.wait_after(1, 10, 0ms);
  ASSERT_EQ(batch.events.size(), 1U);
  EXPECT_EQ(batch.events[0].type, "cell");
  EXPECT_EQ(json::parse(batch.events[0].data)["tool"][2], 1);
}

TEST(ConsoleState, ANewCellRevisionIsKeptAndTold) {
  EventLog log(10, "1");
  ConsoleState state(log);
  EXPECT_TRUE(state.snapshot()["revision"].is_null());
  state.update_revision({{"cell_revision", 4}, {"who", "console:ada"}, {"changes", {{"moved", {{{"id", "part"}}}}}}});
  EXPECT_EQ(state.snapshot()["revision"]["cell_revision"], 4);
  const auto batch = log.wait_after(0, 10, 0ms);
  ASSERT_EQ(batch.events.size(), 1U);
  EXPECT_EQ(batch.events[0].type, "revision");
  EXPECT_EQ(json::parse(batch.events[0].data)["changes"]["moved"][0]["id"], "part");
}

TEST(ConsoleState, AStringThatIsNotUtf8IsReplacedNotThrown) {
  EventLog log(10, "1");
  ConsoleState state(log);
  EXPECT_NO_THROW(state.update_node({{"task_id", "t"}, {"node_id", "n"}, {"message", std::string("bad \xff byte")}}));
  const auto batch = log.wait_after(0, 10, 0ms);
  ASSERT_EQ(batch.events.size(), 1U);
  EXPECT_NE(batch.events[0].data.find("bad \xef\xbf\xbd byte"), std::string::npos) << batch.events[0].data;
}

}  // namespace
}  // namespace rigger::console
