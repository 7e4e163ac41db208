// riggerctl against live processes: a task controller and a scripted executor on the test's own
// domain; every riggerctl command runs as a child process and is judged by its output and exit code.
#include <regex>
#include <string>

#include <gtest/gtest.h>

#include "controller_test_support.hpp"
#include "two_step_recipe.hpp"

namespace rigger::testing::controller {
namespace {

bool contains(const std::string& text, const std::string& part) {
  return text.find(part) != std::string::npos;
}

/// Position of `part` in `text` (npos when absent), for order checks.
std::size_t at(const std::string& text, const std::string& part) {
  return text.find(part);
}

class RiggerctlTest : public ControllerTest {
 protected:
  /// The controller and executor "exec" (Localize, TimerMonitor): Localize succeeds after 0.3 s with two
  /// progress reports unless `nodes` scripts a node id otherwise (each test has its own processes).
  void start_cell(const json& nodes = json::object()) {
    start_controller();
    start_scripted("exec", {"Localize", "TimerMonitor"}, nodes,
                   {{"Localize", {{"mode", "succeed"}, {"delay_s", 0.3}, {"progress_steps", 2}}}});
    wait_ready({"tc", "exec"});
  }

  std::string recipe_file(const std::string& task_id, const json& recipe) {
    return write_file(task_id + ".recipe.json", recipe.dump(2));
  }
};

TEST_F(RiggerctlTest, RunPrintsTheLiveTreeAndExitsZeroOnSuccess) {
  start_cell();
  const auto file = recipe_file("ctl-ok", two_step("ctl-ok"));
  const CtlResult r = ctl("run-ok", {"run", file, "--timeout", "30"});
  ASSERT_EQ(r.code(), 0) << r.output;
  const std::string& out = r.output;
  EXPECT_TRUE(contains(out, "task ctl-ok RUNNING")) << out;
  EXPECT_TRUE(contains(out, "task ctl-ok SUCCEEDED")) << out;
  // Every node's changes, indented by depth, with the executor that runs the leaf.
  const auto load_running = at(out, "  root/0 Skill \"find load\"  RUNNING");
  const auto load_done = at(out, "  root/0 Skill \"find load\"  SUCCESS");
  const auto target_running = at(out, "  root/1 Skill \"find target\"  RUNNING");
  const auto target_done = at(out, "  root/1 Skill \"find target\"  SUCCESS");
  ASSERT_NE(load_running, std::string::npos) << out;
  ASSERT_NE(load_done, std::string::npos) << out;
  ASSERT_NE(target_running, std::string::npos) << out;
  ASSERT_NE(target_done, std::string::npos) << out;
  EXPECT_TRUE(contains(out, "root Sequence \"find both\"  SUCCESS")) << out;
  EXPECT_TRUE(contains(out, "  @exec")) << out;
  // Progress shows up as a percentage on RUNNING lines.
  EXPECT_TRUE(std::regex_search(out, std::regex("root/0 Skill \"find load\"  RUNNING +[0-9]+%"))) << out;
  // Live order: each line when it happened.
  EXPECT_LT(load_running, load_done);
  EXPECT_LT(load_done, target_running);
  EXPECT_LT(target_running, target_done);
  // The last child's SUCCESS and the Sequence's come in one burst; the child's is shown first.
  EXPECT_LT(target_done, at(out, "root Sequence \"find both\"  SUCCESS")) << out;
  EXPECT_LT(target_done, at(out, "task ctl-ok SUCCEEDED"));
}

TEST_F(RiggerctlTest, RunExitsOneAndNamesTheFailingNodeItsCodeAndMessage) {
  start_cell({{"root/1",
               {{"mode", "fail"}, {"delay_s", 0.2}, {"code", "TARGET_NOT_FOUND"}, {"message", "no marker in view"}}}});
  const CtlResult r = ctl("run-fail", {"run", recipe_file("ctl-fail", two_step("ctl-fail")), "--timeout", "30"});
  EXPECT_EQ(r.code(), 1) << r.output;
  const std::string& out = r.output;
  EXPECT_TRUE(contains(out, "  root/0 Skill \"find load\"  SUCCESS")) << out;
  EXPECT_TRUE(contains(out, "  root/1 Skill \"find target\"  FAILURE  @exec  TARGET_NOT_FOUND: no marker in view"))
      << out;
  EXPECT_TRUE(contains(out, "root Sequence \"find both\"  FAILURE  TARGET_NOT_FOUND")) << out;
  // The final report names the failing leaf, its name, the code and the message.
  EXPECT_TRUE(contains(out, "task ctl-fail FAILED at root/1 (find target): TARGET_NOT_FOUND no marker in view")) << out;
  EXPECT_FALSE(contains(out, "SUCCEEDED")) << out;
}

TEST_F(RiggerctlTest, RunOfAnInvalidRecipeExitsOneAndListsEveryError) {
  start_cell();
  json recipe = two_step("ctl-bad");
  recipe["root"]["children"][0]["skill"] = "Teleport";
  recipe["root"]["children"][1]["params"]["min_quality"] = 7;
  const CtlResult r = ctl("run-bad", {"run", recipe_file("ctl-bad", recipe), "--timeout", "30"});
  EXPECT_EQ(r.code(), 1) << r.output;
  EXPECT_TRUE(contains(r.output, "task ctl-bad REJECTED")) << r.output;
  EXPECT_TRUE(contains(r.output, "INVALID_RECIPE")) << r.output;
  EXPECT_TRUE(contains(r.output, "  /root/children/0/skill: ")) << r.output;
  EXPECT_TRUE(contains(r.output, "  /root/children/1/params/min_quality: ")) << r.output;
  EXPECT_TRUE(commands_seen_.empty());
  // A file that is not there is a usage error (2).
  EXPECT_EQ(ctl("run-missing", {"run", cell_.log_dir() + "/no-such-file.json"}).code(), 2);
  // A recipe bigger than any controller accepts (100 MB) is refused before anything is published.
  const std::string huge_file = cell_.log_dir() + "/huge.json";
  std::ofstream(huge_file) << "{\"recipe_version\": 1, \"task_id\": \"ctl-huge\", \"description\": \""
                           << std::string(100U * 1024U * 1024U, 'x') << "\"}";
  const CtlResult huge = ctl("run-huge", {"run", huge_file});
  EXPECT_EQ(huge.code(), 1) << huge.output;
  EXPECT_TRUE(contains(huge.output, "100.0 MB is more than any task controller accepts")) << huge.output;
  EXPECT_TRUE(contains(huge.output, "nothing was sent")) << huge.output;
  EXPECT_EQ(tasks_.count("ctl-huge"), 0U);
}

TEST_F(RiggerctlTest, WithoutAControllerRunAndStatusExitThree) {
  // Nothing runs on the test's domain.
  const CtlResult run = ctl("run-none", {"run", recipe_file("nobody", two_step("nobody")), "--match-timeout", "1"});
  EXPECT_EQ(run.code(), 3) << run.output;
  EXPECT_TRUE(contains(run.output, "no task controller on domain " + std::to_string(cell_.domain_id()))) << run.output;
  const CtlResult status = ctl("status-none", {"status", "--timeout", "1"});
  EXPECT_EQ(status.code(), 3) << status.output;
}

TEST_F(RiggerctlTest, StatusTreeSkillsAndLogDescribeWhatRan) {
  start_cell();
  ASSERT_EQ(ctl("run-ok", {"run", recipe_file("first", two_step("first")), "--quiet"}).code(), 0);
  json failing = two_step("second");
  failing["root"]["children"][1] = {
      {"type", "Inverter"}, {"name", "must not see the target"}, {"child", failing["root"]["children"][1]}};
  ASSERT_EQ(ctl("run-fail", {"run", recipe_file("second", failing), "--quiet"}).code(), 1);

  // status: every task of the journal, newest first, with its state.
  const CtlResult status = ctl("status", {"status"});
  ASSERT_EQ(status.code(), 0) << status.output;
  const auto first = at(status.output, "first ");
  const auto second = at(status.output, "second ");
  ASSERT_NE(first, std::string::npos) << status.output;
  ASSERT_NE(second, std::string::npos) << status.output;
  EXPECT_LT(second, first) << "newest first:\n" << status.output;
  EXPECT_TRUE(contains(status.output.substr(first, status.output.find('\n', first) - first), "SUCCEEDED"))
      << status.output;
  EXPECT_TRUE(contains(status.output.substr(second, status.output.find('\n', second) - second), "FAILED"))
      << status.output;

  // tree: the last state of every node, with the failure's code.
  const CtlResult tree = ctl("tree", {"tree", "second"});
  ASSERT_EQ(tree.code(), 0) << tree.output;
  EXPECT_TRUE(contains(tree.output, "root Sequence \"find both\"  FAILURE  INVERTED")) << tree.output;
  EXPECT_TRUE(contains(tree.output, "  root/0 Skill \"find load\"  SUCCESS  @exec")) << tree.output;
  EXPECT_TRUE(contains(tree.output, "  root/1 Inverter \"must not see the target\"  FAILURE  INVERTED")) << tree.output;
  EXPECT_TRUE(contains(tree.output, "    root/1/0 Skill \"find target\"  SUCCESS")) << tree.output;
  const CtlResult no_tree = ctl("tree-none", {"tree", "never-ran"});
  EXPECT_EQ(no_tree.code(), 1) << no_tree.output;
  EXPECT_TRUE(contains(no_tree.output, "no node status for task never-ran")) << no_tree.output;

  // skills: the live executor and what it offers, with parameter types, units and defaults.
  const CtlResult skills = ctl("skills", {"skills"});
  ASSERT_EQ(skills.code(), 0) << skills.output;
  EXPECT_TRUE(contains(skills.output, "exec (pid ")) << skills.output;
  EXPECT_TRUE(contains(skills.output, "skill     Localize")) << skills.output;
  EXPECT_TRUE(contains(skills.output, "min_quality:number=0.8")) << skills.output;
  EXPECT_TRUE(contains(skills.output, "timeout_s:number[s]=5")) << skills.output;
  EXPECT_TRUE(contains(skills.output, "monitor   TimerMonitor")) << skills.output;

  // log: the journal's timeline: commands sent, events received, node transitions, the result.
  const CtlResult log = ctl("log", {"log", "second"});
  ASSERT_EQ(log.code(), 0) << log.output;
  const std::string& l = log.output;
  EXPECT_TRUE(contains(l, "COMMAND        root/0           START")) << l;
  EXPECT_TRUE(contains(l, "Localize on exec")) << l;
  EXPECT_TRUE(contains(l, "EVENT          root/1/0         SUCCESS")) << l;
  EXPECT_TRUE(contains(l, "NODE           root/1           FAILURE      INVERTED")) << l;
  EXPECT_TRUE(contains(l, "TASK")) << l;
  EXPECT_LT(at(l, "COMMAND        root/0           START"), at(l, "EVENT          root/0           SUCCESS")) << l;
  const CtlResult no_log = ctl("log-none", {"log", "never-ran"});
  EXPECT_EQ(no_log.code(), 1) << no_log.output;
  EXPECT_TRUE(contains(no_log.output, "no such task in the journal")) << no_log.output;
}

// Each riggerctl is a new participant that asks once: before the fix, a reply written while the
// controller's reply writer had not yet matched the new reader reached nobody, and `log`/`tree` exited 3
// now and then against an idle controller. Every one of these queries must be answered.
TEST_F(RiggerctlTest, EveryJournalQueryOfAFreshClientIsAnswered) {
  start_cell();
  ASSERT_EQ(ctl("run-ok", {"run", recipe_file("first", two_step("first")), "--quiet"}).code(), 0);
  constexpr int kQueries = 120;
  int unanswered = 0;
  for (int i = 0; i < kQueries; ++i) {
    const bool tree = i % 2 == 0;
    const CtlResult r = ctl("q-" + std::to_string(i), {tree ? "tree" : "log", "first", "--timeout", "5"});
    if (r.code() != 0) {
      ++unanswered;
      ADD_FAILURE() << "query " << i << " (" << (tree ? "tree" : "log") << ") exited " << r.code() << ":\n"
                    << r.output;
    }
  }
  std::printf("  %d of %d journal queries from fresh riggerctl processes answered\n", kQueries - unanswered, kQueries);
}

TEST_F(RiggerctlTest, CancelStopsARunningTaskAndRunReportsCanceled) {
  start_cell({{"root/0", {{"mode", "run"}, {"stop_delay_s", 0.2}}}});  // runs until shut down
  start_ctl("run-cancel", {"run", recipe_file("ctl-cancel", two_step("ctl-cancel"))});
  ASSERT_TRUE(wait_output("run-cancel", "  root/0 Skill \"find load\"  RUNNING")) << ctl_.at("run-cancel")->log();
  const CtlResult cancel = ctl("cancel", {"cancel", "ctl-cancel", "--reason", "operator went home"});
  EXPECT_EQ(cancel.code(), 0) << cancel.output;
  EXPECT_TRUE(contains(cancel.output, "task ctl-cancel CANCELED")) << cancel.output;
  // The running skill was shut down and answered before the task reported CANCELED.
  const auto* shutdown = command_at("ctl-cancel", "root/0", rigger_skill_SKILL_SHUTDOWN);
  ASSERT_NE(shutdown, nullptr);
  const auto* stopped = event_at("ctl-cancel", "root/0", rigger_skill_SKILL_EVENT_STOPPED);
  ASSERT_NE(stopped, nullptr);
  ASSERT_TRUE(wait_task("ctl-cancel", rigger_task_TASK_CANCELED));
  EXPECT_LE(stopped->at, task_at("ctl-cancel", rigger_task_TASK_CANCELED)->at);
  EXPECT_EQ(command_at("ctl-cancel", "root/1", rigger_skill_SKILL_START), nullptr);

  const CtlResult run = wait_ctl("run-cancel");
  EXPECT_EQ(run.code(), 1) << run.output;
  EXPECT_TRUE(contains(run.output, "  root/0 Skill \"find load\"  STOPPED")) << run.output;
  EXPECT_TRUE(contains(run.output, "task ctl-cancel CANCELED")) << run.output;
  EXPECT_TRUE(contains(run.output, "operator went home")) << run.output;

  const CtlResult log = ctl("log", {"log", "ctl-cancel"});
  EXPECT_TRUE(contains(log.output, "COMMAND                         CANCEL       operator went home")) << log.output;
  EXPECT_TRUE(contains(log.output, "SHUTDOWN")) << log.output;

  // Cancelling what already ended says how it ended (CANCELED: exit 0; anything else: exit 1), and a task
  // the controller never had is an error at once.
  const CtlResult again = ctl("cancel-again", {"cancel", "ctl-cancel"});
  EXPECT_EQ(again.code(), 0) << again.output;
  EXPECT_TRUE(contains(again.output, "task ctl-cancel had already ended: CANCELED")) << again.output;
  const CtlResult unknown = ctl("cancel-unknown", {"cancel", "never-ran"});
  EXPECT_EQ(unknown.code(), 1) << unknown.output;
  EXPECT_TRUE(contains(unknown.output, "no task never-ran (no such task in the journal)")) << unknown.output;
}

}  // namespace
}  // namespace rigger::testing::controller
