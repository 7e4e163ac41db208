// Resume after a crash (issue 13): the controller is SIGKILLed while the second skill of a Sequence of
// three runs, a second controller on the same journal reports the task INTERRUPTED and starts nothing;
// `riggerctl resume` rebuilds it from the journal and asks the operator (prompt kind "resume"); only the
// operator's answer starts anything. Real task_controller, scripted executor and riggerctl processes.
#include <map>
#include <string>

#include <gtest/gtest.h>

#include "controller_test_support.hpp"

namespace rigger::testing::controller {
namespace {

json skill(const std::string& name, const std::string& object) {
  return {{"type", "Skill"}, {"name", name}, {"skill", "Localize"}, {"params", {{"object", object}}}};
}

class ResumeTest : public ControllerTest {
 protected:
  /// Task `task_id`, Sequence [first, second, third]; tc is killed while `second` (2 s) runs, tc-2 is
  /// started on the same journal and has reported the task INTERRUPTED when this returns.
  void crash_in_the_second_skill(const std::string& task_id, bool second_restartable = false) {
    expect_clean_exit_ = false;  // tc is killed
    start_controller();
    start_scripted("exec", {"Localize"},
                   {{"root/0", {{"mode", "succeed"}, {"delay_s", 0.1}}},
                    {"root/1", {{"mode", "succeed"}, {"delay_s", 2.0}}},
                    {"root/2", {{"mode", "succeed"}, {"delay_s", 0.1}}}});
    wait_ready({"tc", "exec"});
    json second = skill("second", "target");
    if (second_restartable) second["restartable"] = true;
    submit(task_id,
           {{"recipe_version", 1},
            {"task_id", task_id},
            {"root", {{"type", "Sequence"}, {"children", {skill("first", "load"), second, skill("third", "load")}}}}});
    ASSERT_TRUE(cell_.wait_until([&] { return event_at(task_id, "root/1", rigger_skill_SKILL_EVENT_ACCEPTED); }, 20s));
    // Killed once the journal holds the second START: the rows of a handler are written right after its
    // commands, so a kill just after a START may lose them (then the first skill counts as interrupted,
    // and the operator decides about it too; ResumePlan.* covers that case).
    ASSERT_TRUE(cell_.wait_until([&] { return has_line(journal(task_id), "root/1", "COMMAND", "START"); }, 10s));
    cell_.loop().on_status(recipes_->handle(), DDS_PUBLICATION_MATCHED_STATUS, [] {});
    ASSERT_TRUE(cell_.stop("tc", SIGKILL, 5s).has_value());
    ASSERT_TRUE(cell_.wait_until([&] { return recipes_->matched_readers() == 0; }, 10s));
    starts_before_ = count_commands(task_id, rigger_skill_SKILL_START);
    start_controller(json::object(), "tc-2");
    wait_ready({"tc-2"});
    ASSERT_TRUE(cell_.wait_until([&] { return code_seen(task_id, "INTERRUPTED"); }, 10s));
  }
  bool code_seen(const std::string& task_id, const std::string& code) const {
    auto it = tasks_.find(task_id);
    if (it == tasks_.end()) return false;
    for (const auto& s : it->second)
      if (s.code == code) return true;
    return false;
  }
  /// The open resume prompt of `task_id` (waits for it).
  const PromptSeen* resume_prompt(const std::string& task_id) {
    cell_.wait_until([&] { return prompt(task_id, "resume") != nullptr && prompt(task_id, "resume")->active; }, 10s);
    return prompt(task_id, "resume");
  }
  /// START rows per node in the journal of `task_id` (both controllers' runs).
  std::map<std::string, int> journaled_starts(const std::string& task_id) {
    std::map<std::string, int> n;
    for (const auto& l : journal(task_id))
      if (l.kind == "COMMAND" && l.code == "START") ++n[l.node];
    return n;
  }

  std::size_t starts_before_ = 0;
};

TEST_F(ResumeTest, KilledInTheSecondSkillAndResumedWithTheOperatorsRerunTheTaskSucceeds) {
  crash_in_the_second_skill("seq");
  EXPECT_EQ(starts_before_, 2U);
  const CtlResult r = ctl("resume", {"resume", "seq"});
  EXPECT_EQ(r.code(), 0) << r.output;
  EXPECT_NE(r.output.find("was INTERRUPTED"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("done, not run again: root/0 (first)"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("the operator decides: rerun, skip = take as done, abort): root/1 (second)"),
            std::string::npos)
      << r.output;
  EXPECT_NE(r.output.find("then, when reached: root/2 (third)"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("riggerctl operator"), std::string::npos) << r.output;
  const PromptSeen* p = resume_prompt("seq");
  ASSERT_NE(p, nullptr);
  EXPECT_EQ(p->options, (std::vector<std::string>{"rerun", "skip", "abort"}));
  EXPECT_EQ(p->prompt_id, "seq#resume#1");
  // Nothing started while the question is open: the journal (answered after the prompt went out) has no
  // START beyond the killed controller's.
  EXPECT_EQ(journaled_starts("seq"), (std::map<std::string, int>{{"root/0", 1}, {"root/1", 1}}));
  EXPECT_EQ(count_commands("seq", rigger_skill_SKILL_START), starts_before_);

  const CtlResult a = ctl("answer", {"operator", "--answer", "seq#resume#1=rerun"});
  EXPECT_EQ(a.code(), 0) << a.output;
  ASSERT_TRUE(wait_finished("seq", 30s));
  EXPECT_EQ(last("seq").state, rigger_task_TASK_SUCCEEDED) << last("seq").code << " " << last("seq").message;
  // Each completed skill ran exactly once; the interrupted one once more, by the operator's choice.
  EXPECT_EQ(journaled_starts("seq"), (std::map<std::string, int>{{"root/0", 1}, {"root/1", 2}, {"root/2", 1}}));
  const auto lines = journal("seq");
  EXPECT_TRUE(has_line(lines, "", "RESUME", "PLAN"));
  EXPECT_TRUE(has_line(lines, "resume", "OPERATOR", "ASK"));
  EXPECT_TRUE(has_line(lines, "", "RESUME", "CONFIRMED"));
  bool answered_by = false;
  for (const auto& l : lines)
    answered_by = answered_by || (l.kind == "OPERATOR" && l.code == "ANSWER" && l.message.rfind("rerun by ", 0) == 0);
  EXPECT_TRUE(answered_by);
  EXPECT_TRUE(has_line(lines, "", "TASK", "INTERRUPTED"));
  EXPECT_TRUE(has_line(lines, "", "TASK", "SUCCEEDED"));
  ASSERT_NE(prompt("seq", "resume"), nullptr);
  EXPECT_FALSE(prompt("seq", "resume")->active) << "the answered prompt is withdrawn";
}

TEST_F(ResumeTest, SkipTakesTheInterruptedSkillAsDoneAndRunsTheRest) {
  crash_in_the_second_skill("skip");
  EXPECT_EQ(ctl("resume", {"resume", "skip"}).code(), 0);
  ASSERT_NE(resume_prompt("skip"), nullptr);
  answer("skip#resume#1", "skip");
  ASSERT_TRUE(wait_finished("skip", 30s));
  EXPECT_EQ(last("skip").state, rigger_task_TASK_SUCCEEDED) << last("skip").code << " " << last("skip").message;
  EXPECT_EQ(journaled_starts("skip"), (std::map<std::string, int>{{"root/0", 1}, {"root/1", 1}, {"root/2", 1}}));
}

TEST_F(ResumeTest, ARestartableSkillIsStartedAgainAfterTheOperatorConfirms) {
  crash_in_the_second_skill("again", true);
  const CtlResult r = ctl("resume", {"resume", "again"});
  EXPECT_EQ(r.code(), 0) << r.output;
  EXPECT_NE(
      r.output.find(
          "runs again (interrupted restartable skills and monitors; conditions, evaluated anew): root/1 (second)"),
      std::string::npos)
      << r.output;
  const PromptSeen* p = resume_prompt("again");
  ASSERT_NE(p, nullptr);
  EXPECT_EQ(p->options, (std::vector<std::string>{"continue", "abort"}));
  EXPECT_EQ(count_commands("again", rigger_skill_SKILL_START), starts_before_) << "nothing before the confirmation";
  answer("again#resume#1", "continue");
  ASSERT_TRUE(wait_finished("again", 30s));
  EXPECT_EQ(last("again").state, rigger_task_TASK_SUCCEEDED) << last("again").code << " " << last("again").message;
  EXPECT_EQ(journaled_starts("again"), (std::map<std::string, int>{{"root/0", 1}, {"root/1", 2}, {"root/2", 1}}));
}

TEST_F(ResumeTest, AbortEndsTheTaskWithItsCodeAndStartsNothing) {
  crash_in_the_second_skill("abort");
  EXPECT_EQ(ctl("resume", {"resume", "abort"}).code(), 0);
  ASSERT_NE(resume_prompt("abort"), nullptr);
  answer("abort#resume#1", "not an option");  // refused, the prompt stays open
  // Answers are state (keep-last per prompt): the next one only once the controller has taken this one.
  ASSERT_TRUE(cell_.wait_until(
      [&] { return has_line(journal("abort"), "resume", "REJECTED_EVENT", "NOT_AN_OPTION"); }, 10s));
  EXPECT_TRUE(prompt("abort", "resume")->active);
  answer("abort#resume#1", "abort");
  ASSERT_TRUE(wait_finished("abort", 20s));
  EXPECT_EQ(last("abort").state, rigger_task_TASK_FAILED);
  EXPECT_EQ(last("abort").code, "RESUME_ABORTED");
  EXPECT_NE(last("abort").message.find("by test-operator"), std::string::npos) << last("abort").message;
  EXPECT_EQ(count_commands("abort", rigger_skill_SKILL_START), starts_before_);
  EXPECT_TRUE(has_line(journal("abort"), "", "TASK", "FAILED"));
  // Ended: a second resume says so; an unknown task is an error too.
  const CtlResult ended = ctl("ended", {"resume", "abort"});
  EXPECT_EQ(ended.code(), 1) << ended.output;
  EXPECT_NE(ended.output.find("had already ended: FAILED"), std::string::npos) << ended.output;
  const CtlResult unknown = ctl("unknown", {"resume", "no-such-task"});
  EXPECT_EQ(unknown.code(), 1) << unknown.output;
  EXPECT_NE(unknown.output.find("no task no-such-task"), std::string::npos) << unknown.output;
}

TEST_F(ResumeTest, ARecipeNoLongerValidIsRefusedWithTheReasonAndTheTaskStaysInterrupted) {
  crash_in_the_second_skill("gone");
  // The only executor offering Localize is gone: the journaled recipe no longer validates.
  ASSERT_TRUE(cell_.stop("exec", SIGINT, 10s).has_value());
  const CtlResult r = ctl("resume", {"resume", "gone"});
  EXPECT_EQ(r.code(), 1) << r.output;
  EXPECT_NE(r.output.find("task gone cannot be resumed: the recipe is no longer valid"), std::string::npos)
      << r.output;
  EXPECT_EQ(prompt("gone", "resume"), nullptr) << "nobody is asked";
  EXPECT_EQ(count_commands("gone", rigger_skill_SKILL_START), starts_before_);
  const auto lines = journal("gone");
  EXPECT_TRUE(has_line(lines, "", "RESUME", "RESUME_REFUSED"));
  EXPECT_FALSE(has_line(lines, "", "TASK", "RUNNING"));
}

}  // namespace
}  // namespace rigger::testing::controller
