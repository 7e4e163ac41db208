#pragma once
/// @file
/// Shared fixture of the controller_*_test.cpp integration tests: the task controller and its peers
/// (scripted executors, monitor_host, world_model) run as real processes on the test's own DDS domain;
/// the test's participant records every task status, node status, skill command, skill event and
/// operator prompt it sees (with the steady-clock time it saw them), submits recipes, sends task
/// commands and operator answers, queries the journal, and runs riggerctl as a child process.
/// Nothing sleeps: every wait runs the test's event loop until a condition holds or a deadline passes.
/// Thread safety: none; everything runs on the test thread.

#include <signal.h>

#include <chrono>
#include <fstream>
#include <map>
#include <set>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "rigger/dds/conversions.hpp"
#include "rigger/dds/partitions.hpp"
#include "rigger/dds/pubsub.hpp"
#include "rigger/dds/sequences.hpp"
#include "rigger/operator_protocol/prompt.hpp"
#include "rigger/protocol/operator.hpp"
#include "rigger/protocol/skill.hpp"
#include "rigger/protocol/task.hpp"
#include "rigger/skill_protocol/executor_endpoint.hpp"
#include "rigger/testing/cell.hpp"
#include "task_controller_node.hpp"

namespace rigger::testing::controller {

using namespace std::chrono_literals;
using Clock = std::chrono::steady_clock;
using nlohmann::json;
namespace tc = rigger::task_controller;

struct TaskSeen {
  int state = -1;
  std::string code, message, failed_node;
  Clock::time_point at;
};
struct NodeSeen {
  int state = -1;
  std::string code, message;
  Clock::time_point at;
};
struct CommandSeen {
  std::string executor, task, node;
  int kind = 0;
  std::uint64_t seq = 0;
  Clock::time_point at;
  dds_time_t written = 0;  ///< the writer's source timestamp (wall clock; one host: comparable across writers)
};
struct EventSeen {
  std::string executor, task, node;
  int kind = 0;
  std::string code;
  std::uint64_t command_seq = 0;
  Clock::time_point at;
  dds_time_t written = 0;  ///< the writer's source timestamp
  std::string message;
};
struct PromptSeen {
  std::string prompt_id, task, node, text;
  std::vector<std::string> options;
  bool active = false;
  Clock::time_point at;
  std::string details_json;
};
struct JournalLine {
  std::string node, kind, code, message;
};

inline bool task_terminal(int s) {
  return s == rigger_task_TASK_REJECTED || s == rigger_task_TASK_SUCCEEDED || s == rigger_task_TASK_FAILED ||
         s == rigger_task_TASK_CANCELED;
}

/// A finished riggerctl run: exit status and everything it printed (stdout and stderr interleaved).
class ControllerTest : public MultiProcessTest {
 protected:
  void SetUp() override {
    auto& p = cell_.participant();
    recipes_ = std::make_unique<dds::Writer<rigger_task_Recipe>>(p, protocol::task::kRecipe);
    task_commands_ = std::make_unique<dds::Writer<rigger_task_TaskCommand>>(p, protocol::task::kCommand);
    responses_ =
        std::make_unique<dds::Writer<rigger_operator_ui_OperatorResponse>>(p, protocol::operator_ui::kResponse);
    journal_queries_ = std::make_unique<dds::Writer<rigger_task_JournalQuery>>(p, protocol::task::kJournalQuery);
    statuses_ = std::make_unique<dds::Reader<rigger_task_TaskStatus>>(p, protocol::task::kStatus);
    nodes_ = std::make_unique<dds::Reader<rigger_task_NodeStatus>>(p, protocol::task::kNodeStatus,
                                                                   dds::qos::state_changes());
    commands_ = std::make_unique<dds::Reader<rigger_skill_SkillCommand>>(p, protocol::skill::kCommand, dds::qos::all_commands());
    events_ = std::make_unique<dds::Reader<rigger_skill_SkillEvent>>(p, protocol::skill::kEvent);
    prompts_ = std::make_unique<dds::Reader<rigger_operator_ui_OperatorPrompt>>(p, protocol::operator_ui::kPrompt);
    journal_replies_ = std::make_unique<dds::Reader<rigger_task_JournalReply>>(p, protocol::task::kJournalReply);
    auto& loop = cell_.loop();
    loop.on_data(*statuses_, [this] {
      statuses_->take([this](const rigger_task_TaskStatus& s, const dds_sample_info_t&) {
        tasks_[dds::to_string(s.task_id)].push_back({static_cast<int>(s.state), dds::to_string(s.code),
                                                     dds::to_string(s.message), dds::to_string(s.failed_node),
                                                     Clock::now()});
      });
    });
    loop.on_data(*nodes_, [this] {
      nodes_->take([this](const rigger_task_NodeStatus& s, const dds_sample_info_t&) {
        nodes_seen_[dds::to_string(s.task_id) + "|" + dds::to_string(s.node_id)].push_back(
            {static_cast<int>(s.state), dds::to_string(s.code), dds::to_string(s.message), Clock::now()});
      });
    });
    loop.on_data(*commands_, [this] {
      commands_->take([this](const rigger_skill_SkillCommand& c, const dds_sample_info_t& info) {
        // A START the controller sent again (no answer yet) is the same command: recorded once, as an
        // executor takes it once. The count of such re-sends is in sent_again_.
        if (!command_seqs_.insert({info.publication_handle, c.seq}).second) {
          ++sent_again_;
          return;
        }
        commands_seen_.push_back({dds::to_string(c.executor_id), dds::to_string(c.task_id), dds::to_string(c.node_id),
                                  static_cast<int>(c.kind), c.seq, Clock::now(), info.source_timestamp});
      });
    });
    loop.on_data(*events_, [this] {
      events_->take([this](const rigger_skill_SkillEvent& e, const dds_sample_info_t& info) {
        events_seen_.push_back({dds::to_string(e.executor_id), dds::to_string(e.task_id), dds::to_string(e.node_id),
                                static_cast<int>(e.kind), dds::to_string(e.code), e.command_seq, Clock::now(),
                                info.source_timestamp, dds::to_string(e.message)});
      });
    });
    loop.on_data(*prompts_, [this] {
      prompts_->take([this](const rigger_operator_ui_OperatorPrompt& pr, const dds_sample_info_t&) {
        prompts_seen_.push_back({dds::to_string(pr.prompt_id), dds::to_string(pr.task_id), dds::to_string(pr.node_id),
                                 dds::to_string(pr.text), dds::to_string_vector(pr.options), pr.active, Clock::now(),
                                 dds::to_string(pr.details_json)});
      });
    });
    loop.on_data(*journal_replies_, [this] {
      journal_replies_->take([this](const rigger_task_JournalReply& r, const dds_sample_info_t&) {
        if (dds::to_string(r.client_id) != kJournalClient) return;
        auto& lines = journal_answers_[r.request_id];
        for (const auto& e : dds::elements(r.entries))
          lines.push_back(
              {dds::to_string(e.node_id), dds::to_string(e.kind), dds::to_string(e.code), dds::to_string(e.message)});
      });
    });
  }

  // --- files and processes ---

  std::string write_file(const std::string& name, const std::string& text) {
    const std::string path = cell_.log_dir() + "/" + name;
    std::ofstream(path) << text;
    return path;
  }
  std::string write_config(const std::string& name, const json& config) {
    return write_file(name + ".json", config.dump(2));
  }

  /// The controller `id` (default "tc") with a journal in the log folder (the same for every id, so a
  /// controller started after another one was killed is its restart); `extra` adds configuration keys.
  void start_controller(const json& extra = json::object(), const std::string& id = "tc") {
    json cfg = {{"journal_path", cell_.log_dir() + "/journal.sqlite"}, {"executor_wait_s", 0.3}};
    cfg.update(extra);
    cell_.start(id, "task_controller", {"--id", id, "--config", write_config(id, cfg)});
  }
  /// A scripted executor `id` offering `skills`; `nodes` scripts behaviours per node id, `behaviours`
  /// per skill name (see services/scripted_executor/src/behaviour.hpp).
  void start_scripted(const std::string& id, const std::vector<std::string>& skills, const json& nodes,
                      const json& behaviours = json::object()) {
    json cfg = {{"skills", skills}, {"nodes", nodes}, {"behaviours", behaviours}};
    cell_.start(id, "scripted_executor", {"--id", id, "--config", write_config(id, cfg)});
  }
  /// Waits until `services` are READY and the controller reads recipes and task commands.
  /// Also waits until this test's command reader matched the controller's writers: the default one and
  /// one per executor partition, which the controller makes when the executor announces itself. A
  /// command written before this reader matched its writer reaches the executor (the controller waits
  /// for that) but not this test.
  void wait_ready(const std::vector<std::string>& services) {
    ASSERT_TRUE(cell_.wait_ready(services, 30s)) << cell_.logs();
    ASSERT_TRUE(recipes_->wait_for_readers(1, 10s));
    ASSERT_TRUE(task_commands_->wait_for_readers(1, 10s));
    std::uint32_t executors = 0, controllers = 0;
    for (const auto& id : services) {
      const auto it = cell_.directory().services().find(id);
      if (it == cell_.directory().services().end()) continue;
      const std::string& kind = it->second.kind;
      if (kind == "task_controller") ++controllers;
      if (kind == "scripted_executor" || kind == "skill_executor" || kind == "monitor_host") ++executors;
    }
    if (controllers == 0) return;
    ASSERT_TRUE(cell_.wait_until([&] { return commands_->matched_writers() >= executors + 1; }, 10s))
        << commands_->matched_writers() << " command writers matched, " << executors + 1 << " expected";
  }

  // --- talking to the controller ---

  void submit(const std::string& task_id, const json& recipe) {
    rigger_task_Recipe r{};
    const std::string text = recipe.dump(), submitter = "test";
    r.task_id = dds::wire_string(task_id);
    r.recipe_json = dds::wire_string(text);
    r.submitter = dds::wire_string(submitter);
    r.stamp = dds::wire_now();
    ASSERT_EQ(recipes_->write(r), DDS_RETCODE_OK);
  }
  void command(const std::string& task_id, rigger_task_TaskCommandKind kind, const std::string& reason) {
    rigger_task_TaskCommand c{};
    const std::string issuer = "test";
    c.task_id = dds::wire_string(task_id);
    c.kind = kind;
    c.reason = dds::wire_string(reason);
    c.issuer = dds::wire_string(issuer);
    c.seq = ++command_seq_;
    c.stamp = dds::wire_now();
    ASSERT_EQ(task_commands_->write(c), DDS_RETCODE_OK);
  }
  void answer(const std::string& prompt_id, const std::string& choice) {
    ASSERT_EQ(operator_protocol::write_response(*responses_, prompt_id, choice, "test-operator", ""), DDS_RETCODE_OK);
  }
  /// The journal's timeline of `task_id` as the controller answers it now (empty on no answer).
  std::vector<JournalLine> journal(const std::string& task_id) {
    if (!journal_queries_->wait_for_readers(1, 10s) ||
        !cell_.wait_until([&] { return journal_replies_->matched_writers() > 0; }, 10s))
      return {};
    rigger_task_JournalQuery q{};
    const std::string client = kJournalClient;
    q.client_id = dds::wire_string(client);
    q.request_id = ++journal_request_;
    q.task_id = dds::wire_string(task_id);
    q.max_entries = 1000;
    const auto id = q.request_id;
    if (journal_queries_->write(q) != DDS_RETCODE_OK) return {};
    cell_.wait_until([&] { return journal_answers_.count(id) > 0; }, 10s);
    return journal_answers_[id];
  }
  static bool has_line(const std::vector<JournalLine>& lines, const std::string& node, const std::string& kind,
                       const std::string& code) {
    for (const auto& l : lines)
      if (l.node == node && l.kind == kind && l.code == code) return true;
    return false;
  }

  // --- what the test saw ---

  bool finished(const std::string& task_id) const {
    auto it = tasks_.find(task_id);
    return it != tasks_.end() && !it->second.empty() && task_terminal(it->second.back().state);
  }
  bool wait_finished(const std::string& task_id, std::chrono::milliseconds timeout = 20s) {
    return cell_.wait_until([&] { return finished(task_id); }, timeout);
  }
  const TaskSeen& last(const std::string& task_id) { return tasks_.at(task_id).back(); }
  const TaskSeen* task_at(const std::string& task_id, int state) const {
    auto it = tasks_.find(task_id);
    if (it == tasks_.end()) return nullptr;
    for (const auto& s : it->second)
      if (s.state == state) return &s;
    return nullptr;
  }
  bool wait_task(const std::string& task_id, int state, std::chrono::milliseconds timeout = 20s) {
    return cell_.wait_until([&] { return task_at(task_id, state) != nullptr; }, timeout);
  }
  const NodeSeen* node_at(const std::string& task_id, const std::string& node_id, int state) const {
    auto it = nodes_seen_.find(task_id + "|" + node_id);
    if (it == nodes_seen_.end()) return nullptr;
    for (const auto& n : it->second)
      if (n.state == state) return &n;
    return nullptr;
  }
  bool wait_node(const std::string& task_id, const std::string& node_id, int state,
                 std::chrono::milliseconds timeout = 20s) {
    return cell_.wait_until([&] { return node_at(task_id, node_id, state) != nullptr; }, timeout);
  }
  const CommandSeen* command_at(const std::string& task_id, const std::string& node_id, int kind) const {
    for (const auto& c : commands_seen_)
      if (c.task == task_id && c.node == node_id && c.kind == kind) return &c;
    return nullptr;
  }
  bool wait_command(const std::string& task_id, const std::string& node_id, int kind,
                    std::chrono::milliseconds timeout = 20s) {
    return cell_.wait_until([&] { return command_at(task_id, node_id, kind) != nullptr; }, timeout);
  }
  std::size_t count_commands(const std::string& task_id, int kind) const {
    std::size_t n = 0;
    for (const auto& c : commands_seen_)
      if (c.task == task_id && c.kind == kind) ++n;
    return n;
  }
  const EventSeen* event_at(const std::string& task_id, const std::string& node_id, int kind) const {
    for (const auto& e : events_seen_)
      if (e.task == task_id && e.node == node_id && e.kind == kind) return &e;
    return nullptr;
  }
  /// The last prompt sample of `task_id`'s node `node_id`, or nullptr.
  const PromptSeen* prompt(const std::string& task_id, const std::string& node_id) const {
    const PromptSeen* found = nullptr;
    for (const auto& p : prompts_seen_)
      if (p.task == task_id && p.node == node_id) found = &p;
    return found;
  }

  // --- riggerctl ---

  /// Starts `riggerctl --domain <ours> args...`; its output goes to <log dir>/<name>.log. It is not one
  /// of the cell's services (an exit code of 1 can be the expected outcome).
  ChildProcess& start_ctl(const std::string& name, const std::vector<std::string>& args) {
    ctl_[name] = start_riggerctl(cell_, name, args);
    return *ctl_[name];
  }
  /// Waits (running the test's loop, so its readers keep up) until riggerctl `name` ended.
  CtlResult wait_ctl(const std::string& name, std::chrono::milliseconds timeout = 30s) {
    ChildProcess& p = *ctl_.at(name);
    cell_.wait_until([&] { return !p.running(); }, timeout);
    CtlResult r;
    r.status = p.wait(1s);
    r.output = p.log();
    return r;
  }
  CtlResult ctl(const std::string& name, const std::vector<std::string>& args,
                std::chrono::milliseconds timeout = 30s) {
    start_ctl(name, args);
    return wait_ctl(name, timeout);
  }
  /// Waits until riggerctl `name` printed `text` (its output is a file: the loop wakes every 20 ms to look).
  bool wait_output(const std::string& name, const std::string& text, std::chrono::milliseconds timeout = 20s) {
    ChildProcess& p = *ctl_.at(name);
    const auto wake = cell_.loop().every(20ms, [] {});
    const bool ok = cell_.wait_until([&] { return p.log().find(text) != std::string::npos; }, timeout);
    cell_.loop().cancel(wake);
    return ok;
  }

  static constexpr const char* kJournalClient = "controller-test";

  std::unique_ptr<dds::Writer<rigger_task_Recipe>> recipes_;
  std::unique_ptr<dds::Writer<rigger_task_TaskCommand>> task_commands_;
  std::unique_ptr<dds::Writer<rigger_operator_ui_OperatorResponse>> responses_;
  std::unique_ptr<dds::Writer<rigger_task_JournalQuery>> journal_queries_;
  std::unique_ptr<dds::Reader<rigger_task_TaskStatus>> statuses_;
  std::unique_ptr<dds::Reader<rigger_task_NodeStatus>> nodes_;
  std::unique_ptr<dds::Reader<rigger_skill_SkillCommand>> commands_;
  std::unique_ptr<dds::Reader<rigger_skill_SkillEvent>> events_;
  std::unique_ptr<dds::Reader<rigger_operator_ui_OperatorPrompt>> prompts_;
  std::unique_ptr<dds::Reader<rigger_task_JournalReply>> journal_replies_;

  std::map<std::string, std::vector<TaskSeen>> tasks_;
  std::map<std::string, std::vector<NodeSeen>> nodes_seen_;  // "task|node"
  std::vector<CommandSeen> commands_seen_;
  /// (writer, seq) of commands_seen_: a controller numbers its commands, a restarted one from 1 again.
  std::set<std::pair<dds_instance_handle_t, std::uint64_t>> command_seqs_;
  std::size_t sent_again_ = 0;  ///< commands seen again with a (writer, seq) already recorded
  std::vector<EventSeen> events_seen_;
  std::vector<PromptSeen> prompts_seen_;
  std::map<std::uint64_t, std::vector<JournalLine>> journal_answers_;
  std::map<std::string, std::unique_ptr<ChildProcess>> ctl_;
  std::uint64_t command_seq_ = 0;
  std::uint64_t journal_request_ = 0;
};

}  // namespace rigger::testing::controller
