// One task (task_port's Task) on a fake TaskHost: PAUSE / RESUME reach the running leaves and are
// journaled with who did it, the leaves' answers are journaled (held, or not pausable and running on),
// and a START held for a busy resource that is freed while the task is paused goes out only on RESUME.
// The host's endpoint writes real SkillCommands on a private domain; the test reads them back.
#include "task_port.hpp"

#include <gtest/gtest.h>

#include "rigger/dds/partitions.hpp"
#include "rigger/dds/conversions.hpp"
#include "rigger/protocol/skill.hpp"
#include "rigger/skill/skill_library.hpp"
#include "rigger/testing/domain.hpp"
#include "unit_test_util.hpp"

namespace rigger::task_controller {
namespace {

using namespace std::chrono_literals;

struct Command {
  std::string node;
  rigger_skill_SkillCommandKind kind;
  std::uint64_t seq;
  std::string reason;
};

class FakeHost final : public TaskHost {
 public:
  FakeHost() = default;

  dds::EventLoop& loop() override { return loop_; }
  const Logger& log() const override { return log_; }
  Task* find_task(const std::string& id) override { return task_ && task_->id() == id ? task_.get() : nullptr; }
  std::string pick_executor(const std::string&, const std::string&) const override { return "exec-1"; }
  std::string holder_of(const std::vector<std::string>&, const std::string&, const std::set<std::string>*,
                        const std::string&) const override {
    return holder_;
  }
  std::chrono::nanoseconds busy_wait() const override { return busy_wait_; }
  unsigned progress_rows_per_run() const override { return 10; }
  ControllerEndpoint& endpoint() override { return endpoint_; }
  PromptWriter& prompts() override { return prompts_; }
  void journal(const JournalRecord& record) override { rows_.push_back(record); }
  void node_status(NodeStatusRow) override {}
  void is_localized(const std::string&, double, std::function<void(const world_client::Reply&)>) override {}
  std::chrono::nanoseconds start_answer_timeout() const override { return 30s; }
  std::chrono::nanoseconds start_resend() const override { return start_resend_; }
  bool safe_stop(const std::string&, const std::string&) override { return true; }
  void task_finished(const std::string&, int state, const std::string&, const bt::TaskResult&,
                     const std::string&) override {
    finished_state_ = state;
  }

  /// Builds the task of `recipe` (skills of the scripted library) and starts its tree.
  Task& start(const nlohmann::json& recipe) {
    const recipe::RecipeValidator validator(skill::SkillLibrary::from_json(
        testing::library_with({"Localize", "Screw", "CollaborativeMoveLoad", "YankMonitor"})));
    auto checked = validator.validate_document(recipe);
    EXPECT_TRUE(checked.errors.empty()) << checked.errors.front().message;
    task_ = std::make_unique<Task>(*this, std::move(*checked.recipe), recipe.at("task_id").get<std::string>());
    task_->log_result("start", "root", task_->engine().start());
    return *task_;
  }
  /// Waits until `n` commands were read (or 5 s passed), then lets 100 ms more pass for extra ones.
  const std::vector<Command>& commands_after(std::size_t n) {
    loop_.run_until([&] { return commands_.size() >= n; }, 5s);
    return commands_now();
  }
  /// The commands read after 200 ms more (a command written before would have arrived by then: one
  /// participant, loopback).
  const std::vector<Command>& commands_now() {
    loop_.run_until([] { return false; }, 200ms);
    return commands_;
  }
  /// Journal rows as "node kind code: message".
  std::vector<std::string> rows(const std::string& kind) const {
    std::vector<std::string> out;
    for (const auto& r : rows_)
      if (r.kind == kind) out.push_back(r.node_id + " " + r.code + ": " + r.message);
    return out;
  }
  /// What the executor answers to the PAUSE or RESUME of `node` (its current run).
  void answer(const std::string& node, skill_protocol::EventKind answer, const std::string& code,
              const std::string& message) {
    ReceivedEvent e = event(node);
    e.outcome = {answer, code, message, std::nullopt};
    task_->on_event(e);
  }
  /// The executor answers the START `start_seq` of `node` (ACCEPTED: it runs).
  void accept(const std::string& node, std::uint64_t start_seq) {
    ReceivedEvent e = event(node);
    e.command_seq = start_seq;
    e.outcome.kind = skill_protocol::EventKind::kAccepted;
    task_->on_event(e);
  }
  /// The leaf `node` (run `start_seq`) reports `kind`.
  void report(const std::string& node, std::uint64_t start_seq, skill_protocol::EventKind kind) {
    ReceivedEvent e = event(node);
    e.command_seq = start_seq;
    e.outcome.kind = kind;
    task_->on_event(e);
  }

  std::uint32_t domain() const { return domain_.id(); }

  std::string holder_;
  std::chrono::nanoseconds busy_wait_ = 30s;
  /// Long by default: the other tests read the commands without answering them.
  std::chrono::nanoseconds start_resend_ = 30s;
  std::vector<JournalRecord> rows_;
  int finished_state_ = -1;

 private:
  rigger::testing::DomainLease domain_;
  dds::Participant participant_{domain_.id()};
  dds::EventLoop loop_{participant_};
  Logger log_ = null_logger();
  ControllerEndpoint endpoint_{participant_, 300ms};
  PromptWriter prompts_{participant_};
  dds::Reader<rigger_skill_SkillCommand> reader_{participant_, protocol::skill::kCommand, dds::qos::all_commands()};
  std::vector<Command> commands_;
  std::uint64_t event_seq_ = 0;
  std::unique_ptr<Task> task_;

  ReceivedEvent event(const std::string& node) {
    ReceivedEvent e;
    e.task_id = task_->id();
    e.node_id = node;
    e.executor_id = "exec-1";
    e.seq = ++event_seq_;
    return e;
  }

  bool subscribed_ = [this] {
    loop_.on_data(reader_, [this] {
      reader_.take([this](const rigger_skill_SkillCommand& c, const dds_sample_info_t&) {
        commands_.push_back({dds::to_string(c.node_id), c.kind, c.seq, dds::to_string(c.reason)});
      });
    });
    return true;
  }();
};

std::vector<std::string> kinds(const std::vector<Command>& commands) {
  std::vector<std::string> out;
  for (const auto& c : commands) {
    const char* k = c.kind == rigger_skill_SKILL_START      ? "START"
                    : c.kind == rigger_skill_SKILL_SHUTDOWN ? "SHUTDOWN"
                    : c.kind == rigger_skill_SKILL_PAUSE    ? "PAUSE"
                                                            : "RESUME";
    out.push_back(std::string(k) + " " + c.node);
  }
  return out;
}

// Localize and the operator's Screw run side by side (M = 2).
nlohmann::json two_leaves(const std::string& task_id) {
  return {{"recipe_version", 1},
          {"task_id", task_id},
          {"assumptions", {"inserted(load,target)"}},
          {"root",
           {{"type", "Parallel"},
            {"success_threshold", 2},
            {"failure_threshold", 1},
            {"children",
             {{{"type", "Skill"}, {"skill", "Localize"}, {"params", {{"object", "load"}}}},
              {{"type", "Skill"},
               {"skill", "Screw"},
               {"params", {{"object", "load"}, {"target", "target"}, {"holes", {"target/h1"}}}}}}}}}};
}

TEST(TaskPause, PauseAndResumeReachEveryRunningLeafAndTheJournalSaysWhoAndWhatEachDid) {
  FakeHost host;
  Task& task = host.start(two_leaves("pause"));
  ASSERT_EQ(kinds(host.commands_after(2)), (std::vector<std::string>{"START root/0", "START root/1"}));
  const std::uint64_t localize_seq = host.commands_after(2)[0].seq, screw_seq = host.commands_after(2)[1].seq;

  EXPECT_EQ(task.command(rigger_task_TASK_PAUSE, "lunch break", "riggerctl:alice"), rigger_task_TASK_PAUSED);
  const auto& paused = host.commands_after(4);
  ASSERT_EQ(kinds(paused), (std::vector<std::string>{"START root/0", "START root/1", "PAUSE root/0", "PAUSE root/1"}));
  EXPECT_GT(paused[2].seq, screw_seq) << "a PAUSE takes a new command seq";
  EXPECT_EQ(paused[2].reason, "lunch break");
  ASSERT_FALSE(host.rows("COMMAND").empty());
  EXPECT_EQ(host.rows("COMMAND")[2], " PAUSE: by riggerctl:alice: lunch break");
  EXPECT_EQ(host.rows("COMMAND")[3], "root/0 PAUSE: Localize on exec-1: lunch break");

  // The answers: Localize holds, the operator's Screw cannot pause and runs on; both are journaled.
  host.answer("root/0", skill_protocol::EventKind::kPaused, "", "Localize holds still in state detect");
  host.answer("root/1", skill_protocol::EventKind::kPaused, "NOT_PAUSABLE", "Screw cannot pause: it keeps running");
  EXPECT_EQ(host.rows("EVENT"), (std::vector<std::string>{"root/0 PAUSED: Localize holds still in state detect",
                                                          "root/1 NOT_PAUSED: NOT_PAUSABLE: Screw cannot pause: it "
                                                          "keeps running"}));
  // A second PAUSE changes nothing and sends nothing.
  EXPECT_EQ(task.command(rigger_task_TASK_PAUSE, "again", "riggerctl:bob"), -1);
  EXPECT_EQ(host.commands_now().size(), 4u);

  // The operator ends the screwing while paused (a leaf that was not paused may end): no RESUME for it.
  host.report("root/1", screw_seq, skill_protocol::EventKind::kSuccess);
  EXPECT_EQ(task.command(rigger_task_TASK_RESUME, "requested by riggerctl:alice", "riggerctl:alice"),
            rigger_task_TASK_RUNNING);
  ASSERT_EQ(kinds(host.commands_after(5)), (std::vector<std::string>{"START root/0", "START root/1", "PAUSE root/0",
                                                                     "PAUSE root/1", "RESUME root/0"}));
  EXPECT_EQ(host.rows("COMMAND").back(), "root/0 RESUME: Localize on exec-1: requested by riggerctl:alice");
  EXPECT_EQ(host.rows("COMMAND").at(6), " RESUME: requested by riggerctl:alice");
  host.answer("root/0", skill_protocol::EventKind::kResumed, "", "Localize continues in state detect");
  host.report("root/0", localize_seq, skill_protocol::EventKind::kSuccess);
  EXPECT_EQ(host.finished_state_, rigger_task_TASK_SUCCEEDED);
}

nlohmann::json one_leaf(const std::string& task_id) {
  return {{"recipe_version", 1},
          {"task_id", task_id},
          {"root", {{"type", "Skill"}, {"skill", "Localize"}, {"params", {{"object", "load"}}}}}};
}

/// A task whose only leaf's START is held (a killed controller's run still holds the camera), paused.
Task& paused_with_a_held_start(FakeHost& host, const std::string& task_id, std::chrono::nanoseconds busy_wait) {
  host.busy_wait_ = busy_wait;
  host.holder_ = "Localize (task old, node root) still stopping";
  Task& task = host.start(one_leaf(task_id));
  EXPECT_TRUE(task.holds_starts());
  EXPECT_EQ(task.command(rigger_task_TASK_PAUSE, "wait", "riggerctl:alice"), rigger_task_TASK_PAUSED);
  return task;
}

// A restarted controller holds a START while a run of the killed one still holds its resource. Freed
// while the task is paused, it is not sent (nothing that moves starts in a paused task) until RESUME.
TEST(TaskPause, AHeldStartFreedWhileThePauseLastsGoesOutOnlyOnResume) {
  FakeHost host;
  Task& task = paused_with_a_held_start(host, "held", 30s);
  host.holder_.clear();
  task.start_held();  // the announcement that frees the camera
  EXPECT_TRUE(host.commands_now().empty()) << "a START was sent while the task was paused";
  EXPECT_TRUE(task.holds_starts());
  const auto waits = host.rows("COMMAND");
  EXPECT_NE(waits.back().find("starts on RESUME"), std::string::npos) << waits.back();
  task.start_held();  // a later announcement: still nothing
  EXPECT_TRUE(host.commands_now().empty());

  EXPECT_EQ(task.command(rigger_task_TASK_RESUME, "go", "riggerctl:alice"), rigger_task_TASK_RUNNING);
  ASSERT_EQ(kinds(host.commands_after(1)), (std::vector<std::string>{"START root"}));
  EXPECT_FALSE(task.holds_starts());
}

// The same when the busy_wait deadline finds the resource free during the pause: no START, and no
// RESOURCE_HELD failure either; RESUME sends it.
TEST(TaskPause, AHeldStartWhoseDeadlineFindsItFreeWhilePausedWaitsForResume) {
  FakeHost host;
  Task& task = paused_with_a_held_start(host, "deadline", 200ms);
  host.holder_.clear();  // freed, but no announcement was handled before the deadline
  ASSERT_TRUE(host.loop().run_until(
      [&] { return host.rows("COMMAND").back().find("starts on RESUME") != std::string::npos; }, 5s))
      << "the deadline did not find the resource free";
  EXPECT_TRUE(host.commands_now().empty()) << "a START was sent while the task was paused";
  EXPECT_EQ(host.finished_state_, -1) << "the leaf failed although its resource was free";
  EXPECT_EQ(task.command(rigger_task_TASK_RESUME, "go", "riggerctl:alice"), rigger_task_TASK_RUNNING);
  ASSERT_EQ(kinds(host.commands_after(1)), (std::vector<std::string>{"START root"}));
}

// Taken again by another run before the RESUME, the START waits again (and can still fail RESOURCE_HELD).
TEST(TaskPause, AHeldStartTakenAgainBeforeTheResumeWaitsAgain) {
  FakeHost host;
  Task& task = paused_with_a_held_start(host, "again", 300ms);
  host.holder_.clear();
  task.start_held();
  host.holder_ = "Localize (task other, node root) running";
  EXPECT_EQ(task.command(rigger_task_TASK_RESUME, "go", "riggerctl:alice"), rigger_task_TASK_RUNNING);
  EXPECT_TRUE(host.commands_now().empty());
  EXPECT_TRUE(host.loop().run_until([&] { return host.finished_state_ >= 0; }, 5s));
  EXPECT_EQ(host.finished_state_, rigger_task_TASK_FAILED);
  const auto events = host.rows("EVENT");
  ASSERT_FALSE(events.empty());
  EXPECT_NE(events.back().find("RESOURCE_HELD"), std::string::npos) << events.back();
  EXPECT_NE(events.back().find("task other"), std::string::npos) << events.back();
}

// An executor is announced a moment before its command reader is discovered (two separate discovery
// messages). A START written in between reached nobody and was lost for good (a volatile reader never
// gets what was written before its writer knew it): the START waits for the reader instead, and goes
// when it is matched.
dds_guid_t guid_of(const dds::Participant& p) {
  dds_guid_t g{};
  EXPECT_EQ(dds_get_guid(p.handle(), &g), DDS_RETCODE_OK);
  return g;
}

TEST(TaskStart, AStartWaitsForItsExecutorsCommandReaderAndThenReachesIt) {
  FakeHost host;
  dds::Participant executor(host.domain());  // announced, no command reader yet
  host.endpoint().executor_seen("exec-1", guid_of(executor), false);
  Task& task = host.start(one_leaf("unreached"));
  EXPECT_TRUE(task.holds_starts()) << "a START went to an executor whose reader nobody had matched";
  EXPECT_TRUE(host.commands_now().empty());
  const auto waits = host.rows("COMMAND");
  ASSERT_EQ(waits.size(), 1u);
  EXPECT_NE(waits[0].find("START_WAITS"), std::string::npos) << waits[0];
  EXPECT_NE(waits[0].find("exec-1, whose command reader"), std::string::npos) << waits[0];

  dds::EventLoop executor_loop(executor);
  dds::Reader<rigger_skill_SkillCommand> reader(executor, protocol::skill::kCommand,
                                                dds::qos::executor_commands("exec-1"));
  std::vector<std::string> received;
  executor_loop.on_data(reader, [&] {
    reader.take([&](const rigger_skill_SkillCommand& c, const dds_sample_info_t&) {
      received.push_back(dds::to_string(c.node_id));
    });
  });
  const auto deadline = std::chrono::steady_clock::now() + 10s;
  while (!host.endpoint().reachable("exec-1") && std::chrono::steady_clock::now() < deadline)
    executor_loop.run_once(1ms);
  ASSERT_TRUE(host.endpoint().reachable("exec-1")) << "the executor's reader was never matched";
  task.start_held();  // what the node does on PUBLICATION_MATCHED
  EXPECT_FALSE(task.holds_starts());
  ASSERT_TRUE(executor_loop.run_until([&] { return !received.empty(); }, 5s)) << "the START never reached the executor";
  EXPECT_EQ(received, (std::vector<std::string>{"root"}));
}

// A START that got no answer is sent again, with its seq, until an answer comes: a reader that had not
// yet had its writer's first heartbeat drops what came before, though both ends were discovered.
TEST(TaskStart, AnUnansweredStartIsSentAgainWithItsSeqUntilAnswered) {
  FakeHost host;
  host.start_resend_ = 300ms;
  host.start(one_leaf("resend"));
  const auto first = host.commands_after(2);  // the START, then the same again 300 ms later
  ASSERT_EQ(kinds(first), (std::vector<std::string>{"START root", "START root"}));
  EXPECT_EQ(first[0].seq, first[1].seq);
  const auto again = host.rows("COMMAND");
  ASSERT_EQ(again.size(), 2u);
  EXPECT_NE(again[0].find("root START: Localize on exec-1 seq"), std::string::npos) << again[0];
  EXPECT_NE(again[1].find("START_SENT_AGAIN"), std::string::npos) << again[1];
  EXPECT_NE(again[1].find("no answer after 0.3 s"), std::string::npos) << again[1];

  host.accept("root", first[0].seq);
  // The next one would have gone 600 ms after the first resend.
  host.loop().run_until([] { return false; }, 800ms);
  EXPECT_EQ(host.commands_now().size(), first.size()) << "sent again after the answer";
  EXPECT_EQ(host.rows("COMMAND").size(), 2u);
}

// Never discovered: after busy_wait the leaf fails START_UNANSWERED (the START could not be delivered),
// not RESOURCE_HELD.
TEST(TaskStart, AStartWhoseExecutorsReaderNeverAppearsFailsStartUnanswered) {
  FakeHost host;
  host.busy_wait_ = 200ms;
  dds::Participant executor(host.domain());
  host.endpoint().executor_seen("exec-1", guid_of(executor), false);
  host.start(one_leaf("never"));
  ASSERT_TRUE(host.loop().run_until([&] { return host.finished_state_ >= 0; }, 5s));
  EXPECT_EQ(host.finished_state_, rigger_task_TASK_FAILED);
  EXPECT_TRUE(host.commands_now().empty());
  const auto events = host.rows("EVENT");
  ASSERT_FALSE(events.empty());
  EXPECT_NE(events.back().find("START_UNANSWERED"), std::string::npos) << events.back();
  EXPECT_NE(events.back().find("not discovered"), std::string::npos) << events.back();
}

}  // namespace
}  // namespace rigger::task_controller
