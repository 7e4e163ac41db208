// Acceptance of the task controller with real processes: the controller, scripted
// executors and this test's own participant on a private domain. The test observes the skill
// commands the executors receive, the node status and the task status; it never sleeps.
#include <signal.h>

#include <algorithm>
#include <cstdint>
#include <fstream>
#include <iostream>
#include <map>
#include <set>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <sqlite3.h>

#include <nlohmann/json.hpp>

#include "rigger/dds/conversions.hpp"
#include "rigger/dds/partitions.hpp"
#include "rigger/dds/pubsub.hpp"
#include "rigger/dds/sequences.hpp"
#include "rigger/protocol/skill.hpp"
#include "rigger/protocol/task.hpp"
#include "rigger/skill_protocol/executor_endpoint.hpp"
#include "rigger/testing/cell.hpp"
#include "task_controller_node.hpp"

namespace rigger::testing {
namespace {

using namespace std::chrono_literals;
using Clock = std::chrono::steady_clock;
namespace tc = rigger::task_controller;

struct SeenStatus {
  int state = -1;
  std::string code, message, failed_node;
  std::vector<std::string> errors;  // "pointer: message"
  Clock::time_point at;
};
struct SeenNode {
  int state = -1;
  std::string code;
  Clock::time_point at;
};
struct SeenCommand {
  std::string executor, task, node;
  int kind = 0;
  Clock::time_point at;
  std::uint64_t seq = 0;
};
struct SeenEvent {
  std::string task;
  std::uint64_t command_seq = 0;
};

bool terminal(int s) {
  return s == rigger_task_TASK_REJECTED || s == rigger_task_TASK_SUCCEEDED || s == rigger_task_TASK_FAILED ||
         s == rigger_task_TASK_CANCELED;
}

/// Skill ‖ two monitors: Localize (camera) with YankMonitor and ForceMonitor, M = 1, K = 1.
std::string paper_pattern(const std::string& task_id) {
  nlohmann::json r = {
      {"recipe_version", 1},
      {"task_id", task_id},
      {"root",
       {{"type", "Parallel"},
        {"success_threshold", 1},
        {"failure_threshold", 1},
        {"stop_timeout_s", 2},
        {"children",
         {{{"type", "Skill"}, {"skill", "Localize"}, {"params", {{"object", "load"}}}},
          {{"type", "Monitor"}, {"monitor", "YankMonitor"}, {"params", nlohmann::json::object()}},
          {{"type", "Monitor"}, {"monitor", "ForceMonitor"}, {"params", {{"max_force_n", 250}}}}}}}}};
  return r.dump();
}

class TaskControllerTest : public MultiProcessTest {
 protected:
  void SetUp() override {
    auto& p = cell_.participant();
    recipes_ = std::make_unique<dds::Writer<rigger_task_Recipe>>(p, protocol::task::kRecipe);
    // A writer that waits long enough for a 100 MB sample to go out (commands() gives up after 100 ms).
    patient_recipes_ = std::make_unique<dds::Writer<rigger_task_Recipe>>(
        p, protocol::task::kRecipe, dds::qos::commands().reliable(std::chrono::seconds(60)));
    statuses_ = std::make_unique<dds::Reader<rigger_task_TaskStatus>>(p, protocol::task::kStatus);
    nodes_ = std::make_unique<dds::Reader<rigger_task_NodeStatus>>(p, protocol::task::kNodeStatus,
                                                                   dds::qos::state_changes());
    commands_ = std::make_unique<dds::Reader<rigger_skill_SkillCommand>>(p, protocol::skill::kCommand, dds::qos::all_commands());
    events_ = std::make_unique<dds::Reader<rigger_skill_SkillEvent>>(p, protocol::skill::kEvent);
    cell_.loop().on_data(*events_, [this] {
      events_->take([this](const rigger_skill_SkillEvent& e, const dds_sample_info_t&) {
        events_seen_.push_back({dds::to_string(e.task_id), e.command_seq});
      });
    });
    cell_.loop().on_data(*statuses_, [this] {
      statuses_->take([this](const rigger_task_TaskStatus& s, const dds_sample_info_t&) {
        SeenStatus seen{static_cast<int>(s.state), dds::to_string(s.code), dds::to_string(s.message),
                        dds::to_string(s.failed_node), {}, Clock::now()};
        for (const auto& e : dds::elements(s.errors))
          seen.errors.push_back(dds::to_string(e.pointer) + ": " + dds::to_string(e.message));
        status_[dds::to_string(s.task_id)].push_back(seen);
      });
    });
    cell_.loop().on_data(*nodes_, [this] {
      nodes_->take([this](const rigger_task_NodeStatus& s, const dds_sample_info_t&) {
        node_[dds::to_string(s.task_id) + "|" + dds::to_string(s.node_id)].push_back(
            {static_cast<int>(s.state), dds::to_string(s.code), Clock::now()});
      });
    });
    cell_.loop().on_data(*commands_, [this] {
      commands_->take([this](const rigger_skill_SkillCommand& c, const dds_sample_info_t& info) {
        // A START sent again (no answer yet) is the same command, taken once as an executor takes it.
        if (!command_seqs_.insert({info.publication_handle, c.seq}).second) return;
        commands_seen_.push_back({dds::to_string(c.executor_id), dds::to_string(c.task_id), dds::to_string(c.node_id),
                                  static_cast<int>(c.kind), Clock::now(), c.seq});
      });
    });
    journal_path_ = cell_.log_dir() + "/journal.sqlite";
  }

  std::string write_config(const std::string& name, const nlohmann::json& config) {
    const std::string path = cell_.log_dir() + "/" + name + ".json";
    std::ofstream(path) << config.dump(2);
    return path;
  }

  void start_controller(const nlohmann::json& extra = nlohmann::json::object()) {
    nlohmann::json config = {{"journal_path", journal_path_}, {"executor_wait_s", 0.5}};
    config.update(extra);
    cell_.start("tc", "task_controller", {"--id", "tc", "--config", write_config("tc", config)});
  }

  /// exec-skills offers Localize, exec-monitors the two monitors; `nodes` scripts behaviours per node id.
  void start_executors(const nlohmann::json& skill_nodes, const nlohmann::json& monitor_nodes) {
    cell_.start("exec-skills", "scripted_executor",
                {"--id", "exec-skills", "--config",
                 write_config("exec-skills", {{"skills", {"Localize"}}, {"nodes", skill_nodes}})});
    cell_.start("exec-monitors", "scripted_executor",
                {"--id", "exec-monitors", "--config",
                 write_config("exec-monitors", {{"skills", {"YankMonitor", "ForceMonitor"}}, {"nodes", monitor_nodes}})});
  }

  void start_all(const nlohmann::json& skill_nodes, const nlohmann::json& monitor_nodes,
                 const nlohmann::json& controller_config = nlohmann::json::object()) {
    start_controller(controller_config);
    start_executors(skill_nodes, monitor_nodes);
    ASSERT_TRUE(cell_.wait_ready({"tc", "exec-skills", "exec-monitors"}, 20s));
    ASSERT_TRUE(recipes_->wait_for_readers(1, 10s));
    // This test reads every command: the controller's default writer and one per executor partition,
    // made when the executor announces itself. A command written before this reader matched that writer
    // would reach the executor but not this test.
    ASSERT_TRUE(cell_.wait_until([&] { return commands_->matched_writers() >= 3; }, 10s));
  }

  void submit(const std::string& task_id, const std::string& text, bool patient = false) {
    rigger_task_Recipe r{};
    const std::string submitter = "test";
    r.task_id = dds::wire_string(task_id);
    r.recipe_json = dds::wire_string(text);
    r.submitter = dds::wire_string(submitter);
    r.stamp = dds::wire_now();
    ASSERT_EQ((patient ? patient_recipes_ : recipes_)->write(r), DDS_RETCODE_OK);
  }

  bool finished(const std::string& task_id) const {
    auto it = status_.find(task_id);
    return it != status_.end() && !it->second.empty() && terminal(it->second.back().state);
  }
  const SeenStatus& last(const std::string& task_id) { return status_.at(task_id).back(); }
  bool wait_finished(const std::string& task_id, std::chrono::milliseconds timeout = 20s) {
    return cell_.wait_until([&] { return finished(task_id); }, timeout);
  }
  bool node_reached(const std::string& task_id, const std::string& node_id, int state) const {
    auto it = node_.find(task_id + "|" + node_id);
    if (it == node_.end()) return false;
    for (const auto& n : it->second)
      if (n.state == state) return true;
    return false;
  }
  const SeenNode* node_at(const std::string& task_id, const std::string& node_id, int state) const {
    auto it = node_.find(task_id + "|" + node_id);
    if (it == node_.end()) return nullptr;
    for (const auto& n : it->second)
      if (n.state == state) return &n;
    return nullptr;
  }
  /// One row of the journal's timeline table, read straight from the file (the ids are not in the API).
  struct JournalRow {
    long long id = 0;
    std::string task, kind, code, message;
  };
  std::vector<JournalRow> journal_rows() const {
    std::vector<JournalRow> rows;
    sqlite3* db = nullptr;
    if (sqlite3_open_v2(journal_path_.c_str(), &db, SQLITE_OPEN_READONLY, nullptr) == SQLITE_OK) {
      sqlite3_stmt* st = nullptr;
      if (sqlite3_prepare_v2(db, "SELECT id, task_id, kind, code, message FROM records ORDER BY id;", -1, &st,
                             nullptr) == SQLITE_OK) {
        const auto text = [st](int col) {
          const auto* t = sqlite3_column_text(st, col);
          return t ? std::string(reinterpret_cast<const char*>(t)) : std::string();
        };
        while (sqlite3_step(st) == SQLITE_ROW)
          rows.push_back({sqlite3_column_int64(st, 0), text(1), text(2), text(3), text(4)});
      }
      sqlite3_finalize(st);
    }
    sqlite3_close(db);
    return rows;
  }
  std::size_t count_commands(const std::string& task_id, int kind) const {
    std::size_t n = 0;
    for (const auto& c : commands_seen_)
      if (c.task == task_id && c.kind == kind) ++n;
    return n;
  }

  std::unique_ptr<dds::Writer<rigger_task_Recipe>> recipes_, patient_recipes_;
  std::unique_ptr<dds::Reader<rigger_task_TaskStatus>> statuses_;
  std::unique_ptr<dds::Reader<rigger_task_NodeStatus>> nodes_;
  std::unique_ptr<dds::Reader<rigger_skill_SkillCommand>> commands_;
  std::unique_ptr<dds::Reader<rigger_skill_SkillEvent>> events_;
  std::map<std::string, std::vector<SeenStatus>> status_;
  std::map<std::string, std::vector<SeenNode>> node_;
  void kill_in_a_burst(int flush_delay_us);
  std::vector<SeenCommand> commands_seen_;
  std::set<std::pair<dds_instance_handle_t, std::uint64_t>> command_seqs_;  ///< (writer, seq) of commands_seen_
  std::vector<SeenEvent> events_seen_;
  std::string journal_path_;
};

TEST_F(TaskControllerTest, SkillWithMonitorsSucceedsWhenTheSkillDoesAndStopsTheMonitorsFirst) {
  start_all({{"root/0", {{"mode", "succeed"}, {"delay_s", 0.3}, {"progress_steps", 2}}}}, nlohmann::json::object());
  submit("ok", paper_pattern("ok"));
  ASSERT_TRUE(wait_finished("ok"));
  const auto& s = last("ok");
  ASSERT_EQ(s.state, rigger_task_TASK_SUCCEEDED) << s.code << " " << s.message;
  ASSERT_TRUE(node_reached("ok", "root/0", rigger_task_NODE_SUCCESS));
  // Both monitors were shut down and acknowledged before the task reported.
  for (const char* monitor : {"root/1", "root/2"}) {
    const SeenNode* stopped = node_at("ok", monitor, rigger_task_NODE_STOPPED);
    ASSERT_NE(stopped, nullptr) << monitor;
    EXPECT_LE(stopped->at, s.at) << monitor;
  }
  EXPECT_EQ(count_commands("ok", rigger_skill_SKILL_START), 3U);
  EXPECT_EQ(count_commands("ok", rigger_skill_SKILL_SHUTDOWN), 2U);
}

TEST_F(TaskControllerTest, AFiringMonitorFailsTheParallelAfterTheSkillStopped) {
  start_all({{"root/0", {{"mode", "run"}, {"stop_delay_s", 0.2}}}},
            {{"root/1", {{"mode", "fail"}, {"delay_s", 0.3}, {"code", "YANK_DETECTED"}}}});
  submit("yank", paper_pattern("yank"));
  ASSERT_TRUE(wait_finished("yank"));
  const auto& s = last("yank");
  EXPECT_EQ(s.state, rigger_task_TASK_FAILED);
  EXPECT_EQ(s.code, "YANK_DETECTED");
  EXPECT_EQ(s.failed_node, "root/1");
  const SeenNode* stopped = node_at("yank", "root/0", rigger_task_NODE_STOPPED);
  ASSERT_NE(stopped, nullptr);
  EXPECT_LE(stopped->at, s.at);
  const SeenNode* fired = node_at("yank", "root/1", rigger_task_NODE_FAILURE);
  ASSERT_NE(fired, nullptr);
  // The skill's stop takes 200 ms by script; everything else is messaging.
  EXPECT_LT(s.at - fired->at, 1000ms);
}

TEST_F(TaskControllerTest, KilledExecutorFailsItsLeafWithExecutorLostAndStopsSiblingsWithin500ms) {
  expect_clean_exit_ = false;
  start_all({{"root/0", {{"mode", "run"}}}}, nlohmann::json::object());
  submit("kill", paper_pattern("kill"));
  ASSERT_TRUE(cell_.wait_until([&] { return count_commands("kill", rigger_skill_SKILL_START) == 3; }, 10s));
  const auto t0 = Clock::now();
  ASSERT_TRUE(cell_.process("exec-skills").signal(SIGKILL));
  ASSERT_TRUE(wait_finished("kill", 5s));
  const auto took = Clock::now() - t0;
  const auto& s = last("kill");
  EXPECT_EQ(s.state, rigger_task_TASK_FAILED);
  EXPECT_EQ(s.code, "EXECUTOR_LOST");
  EXPECT_EQ(s.failed_node, "root/0");
  EXPECT_TRUE(node_reached("kill", "root/1", rigger_task_NODE_STOPPED));
  EXPECT_TRUE(node_reached("kill", "root/2", rigger_task_NODE_STOPPED));
  std::cout << "SIGKILL → task FAILED(EXECUTOR_LOST), monitors stopped: "
            << std::chrono::duration_cast<std::chrono::milliseconds>(took).count() << " ms\n";
  EXPECT_LT(took, 500ms);
}

TEST_F(TaskControllerTest, HungExecutorFailsItsLeafWithExecutorLostWithin500ms) {
  expect_clean_exit_ = false;
  start_all({{"root/0", {{"mode", "run"}}}}, nlohmann::json::object());
  submit("hang", paper_pattern("hang"));
  ASSERT_TRUE(cell_.wait_until([&] { return count_commands("hang", rigger_skill_SKILL_START) == 3; }, 10s));
  const auto t0 = Clock::now();
  ASSERT_TRUE(cell_.process("exec-skills").signal(SIGSTOP));
  ASSERT_TRUE(wait_finished("hang", 5s));
  const auto took = Clock::now() - t0;
  cell_.process("exec-skills").signal(SIGKILL);
  const auto& s = last("hang");
  EXPECT_EQ(s.state, rigger_task_TASK_FAILED);
  EXPECT_EQ(s.code, "EXECUTOR_LOST");
  EXPECT_TRUE(node_reached("hang", "root/1", rigger_task_NODE_STOPPED));
  EXPECT_TRUE(node_reached("hang", "root/2", rigger_task_NODE_STOPPED));
  std::cout << "SIGSTOP → task FAILED(EXECUTOR_LOST): "
            << std::chrono::duration_cast<std::chrono::milliseconds>(took).count() << " ms\n";
  EXPECT_LT(took, 500ms);
}

TEST_F(TaskControllerTest, HostileRecipesAreRejectedWithAReasonAndNothingStarts) {
  start_all(nlohmann::json::object(), nlohmann::json::object());
  std::map<std::string, std::string> hostile;
  hostile["deep"] = std::string(1'000'000, '[') + std::string(1'000'000, ']');
  // 100 MB, 25 times the controller's 4 MB bound, through DDS (a writer that waits for it to go out).
  hostile["huge"] = "{\"recipe_version\": 1, \"task_id\": \"huge\", \"description\": \"" +
                    std::string(100U * 1024U * 1024U, 'x') + "\"}";
  hostile["types"] = R"({"recipe_version": "one", "task_id": "types", "root": {"type": "Sequence", "children": 5}})";
  auto unknown = nlohmann::json::parse(paper_pattern("unknown"));
  unknown["root"]["children"][0]["skill"] = "Teleport";
  hostile["unknown"] = unknown.dump();
  auto thresholds = nlohmann::json::parse(paper_pattern("thresholds"));
  thresholds["root"]["success_threshold"] = 2;  // only one child can succeed
  hostile["thresholds"] = thresholds.dump();
  auto conflict = nlohmann::json::parse(paper_pattern("conflict"));
  conflict["root"]["children"][1] = {{"type", "Skill"}, {"skill", "Localize"}, {"params", {{"object", "target"}}}};
  hostile["conflict"] = conflict.dump();  // two branches claim the camera
  hostile["utf8"] = "{\"recipe_version\": 1, \"task_id\": \"utf8\", \"description\": \"\xc3\x28\", \"root\": {}}";
  // One at a time: a multi-megabyte sample keeps the reliable writer busy beyond its max_blocking.
  for (const auto& [id, text] : hostile) {
    const auto t0 = Clock::now();
    submit(id, text, id == "huge");
    ASSERT_TRUE(wait_finished(id, 60s)) << id;
    if (id == "huge")
      std::cout << "100 MB recipe: write + rejection took "
                << std::chrono::duration_cast<std::chrono::milliseconds>(Clock::now() - t0).count() << " ms\n";
  }
  for (const auto& [id, text] : hostile) {
    const auto& s = last(id);
    EXPECT_EQ(s.state, rigger_task_TASK_REJECTED) << id;
    EXPECT_FALSE(s.errors.empty() && s.message.empty()) << id;
    std::cout << id << ": " << s.code << " " << (s.errors.empty() ? s.message : s.errors.front()) << "\n";
  }
  EXPECT_TRUE(commands_seen_.empty());
  // The controller keeps serving.
  submit("after", paper_pattern("after"));
  ASSERT_TRUE(wait_finished("after"));
  EXPECT_EQ(last("after").state, rigger_task_TASK_SUCCEEDED) << last("after").code << " " << last("after").message;
}

TEST_F(TaskControllerTest, RestartedControllerReportsTheTaskInterruptedAndStartsNothing) {
  expect_clean_exit_ = false;
  start_all({{"root/0", {{"mode", "run"}}}}, nlohmann::json::object());
  submit("crash", paper_pattern("crash"));
  ASSERT_TRUE(cell_.wait_until([&] { return count_commands("crash", rigger_skill_SKILL_START) == 3; }, 10s));
  ASSERT_TRUE(cell_.stop("tc", SIGKILL, 5s).has_value());
  const std::size_t commands_before = commands_seen_.size();
  status_.erase("crash");
  cell_.start("tc-2", "task_controller",
              {"--id", "tc-2", "--config", write_config("tc-2", {{"journal_path", journal_path_}})});
  ASSERT_TRUE(cell_.wait_until([&] { return finished("crash"); }, 20s));
  const auto& s = last("crash");
  EXPECT_EQ(s.state, rigger_task_TASK_FAILED);
  EXPECT_EQ(s.code, "INTERRUPTED");
  ASSERT_TRUE(cell_.wait_ready({"tc-2"}, 20s));
  EXPECT_EQ(commands_seen_.size(), commands_before);
}

/// Kills the controller in a burst of SUCCESS -> START (the skill succeeds at once: Repeat(Localize), one
/// run at a time) and checks that its journal is a prefix of what happened. Commands go out before their
/// rows are written: rows are handed to the writer thread `flush_delay_us` after the first row of a group
/// (0: right after each handler), and the writer puts everything queued into one transaction. So the
/// kill loses only what was handed over while the last transaction ran, or after it: every START missing
/// from the journal went out just before the kill.
void TaskControllerTest::kill_in_a_burst(int flush_delay_us) {
  expect_clean_exit_ = false;
  start_all({{"root/0", {{"mode", "succeed"}, {"delay_s", 0}}}}, nlohmann::json::object(),
            {{"flush_delay_us", flush_delay_us}});
  const nlohmann::json recipe = {
      {"recipe_version", 1},
      {"task_id", "burst"},
      {"root",
       {{"type", "Repeat"},
        {"repetitions", 1000000},
        {"child", {{"type", "Skill"}, {"skill", "Localize"}, {"params", {{"object", "load"}}}}}}}};
  submit("burst", recipe.dump());
  ASSERT_TRUE(cell_.wait_until([&] { return count_commands("burst", rigger_skill_SKILL_START) >= 300; }, 30s));
  const auto killed_at = Clock::now();
  ASSERT_TRUE(cell_.stop("tc", SIGKILL, 5s).has_value());  // by its pid, in the middle of the burst
  EXPECT_FALSE(finished("burst"));
  status_.erase("burst");
  cell_.start("tc-2", "task_controller",
              {"--id", "tc-2", "--config", write_config("tc-2", {{"journal_path", journal_path_}})});
  ASSERT_TRUE(cell_.wait_until([&] { return finished("burst"); }, 20s));
  EXPECT_EQ(last("burst").state, rigger_task_TASK_FAILED);
  EXPECT_EQ(last("burst").code, "INTERRUPTED");
  ASSERT_TRUE(cell_.wait_ready({"tc-2"}, 20s));

  // What happened: every START the killed controller wrote that reached this test's reader or the
  // executor (which answers each START it takes, and lives on). Reliable delivery needs the writer: a
  // datagram dropped while the controller dies is never sent again, so on a loaded machine this test's
  // reader (it takes every command, event and status) can miss the last STARTs that the executor got.
  std::set<std::uint64_t> witnessed, seen_here;
  for (const auto& c : commands_seen_)
    if (c.task == "burst" && c.kind == rigger_skill_SKILL_START) {
      witnessed.insert(c.seq);
      // The restarted controller numbers its commands from 1 again: a START of its would repeat a seq.
      EXPECT_TRUE(seen_here.insert(c.seq).second) << "START seq " << c.seq << " twice: the restarted controller started something";
    }
  for (const auto& e : events_seen_)
    if (e.task == "burst" && e.command_seq != 0) witnessed.insert(e.command_seq);
  const std::vector<std::uint64_t> sent(witnessed.begin(), witnessed.end());
  for (std::size_t i = 0; i < sent.size(); ++i) ASSERT_EQ(sent[i], i + 1) << "the controller skipped a seq";

  // What the journal kept: rows numbered without a gap, the STARTs a prefix of those sent, and between
  // two STARTs the SUCCESS that caused the second (a row lost before a durable one would show here).
  const auto rows = journal_rows();
  ASSERT_FALSE(rows.empty());
  std::vector<std::uint64_t> journalled;
  std::size_t events_since_start = 0;
  for (std::size_t i = 0; i < rows.size(); ++i) {
    const auto& r = rows[i];
    ASSERT_EQ(r.id, static_cast<long long>(i + 1)) << "gap in the journal's row ids";
    EXPECT_EQ(r.task, "burst");
    if (r.kind == "EVENT") {
      EXPECT_EQ(r.code, "SUCCESS");
      ++events_since_start;
    }
    if (r.kind != "COMMAND" || r.code == "START_SENT_AGAIN") continue;  // no answer yet: the same START again
    ASSERT_EQ(r.code, "START") << r.message;
    const auto at = r.message.find(" seq ");
    ASSERT_NE(at, std::string::npos) << r.message;
    journalled.push_back(std::stoull(r.message.substr(at + 5)));
    EXPECT_EQ(events_since_start, journalled.size() == 1 ? 0U : 1U) << "before START seq " << journalled.back();
    events_since_start = 0;
  }
  // The last group's EVENT row would have come with the START it caused.
  EXPECT_EQ(events_since_start, 0U);
  ASSERT_FALSE(journalled.empty());
  for (std::size_t i = 0; i < journalled.size(); ++i) ASSERT_EQ(journalled[i], i + 1) << "gap in the STARTs journalled";
  EXPECT_LE(journalled.size(), sent.size()) << "the journal holds a START that was never sent";
  // Only the last writes are lost: every START missing from the journal went out in the window of the
  // group being gathered and the transaction being written right before the kill. 100 ms allows for the
  // scheduling of a loaded machine; the burst before it ran for hundreds of STARTs.
  for (const auto& c : commands_seen_) {
    if (c.task != "burst" || c.kind != rigger_skill_SKILL_START || c.seq <= journalled.size()) continue;
    EXPECT_LT(killed_at - c.at, 100ms) << "START seq " << c.seq << " went out "
                                       << std::chrono::duration<double>(killed_at - c.at).count()
                                       << " s before the kill and is not in the journal";
  }
  std::cout << "killed after " << sent.size() << " STARTs (" << seen_here.size() << " seen by this test); journal: "
            << rows.size() << " rows, " << journalled.size() << " STARTs\n";
}

TEST_F(TaskControllerTest, ControllerKilledInABurstLeavesAJournalThatIsAPrefixOfWhatHappened) {
  kill_in_a_burst(1000);  // the default: rows flushed in groups, 1 ms after a group's first row
}

TEST_F(TaskControllerTest, ControllerKilledInABurstWithoutFlushDelayLosesOnlyTheLastWrites) {
  kill_in_a_burst(0);
}

}  // namespace
}  // namespace rigger::testing
