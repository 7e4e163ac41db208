// Resume after a crash: the controller is SIGKILLed while the second skill of a Sequence of
// three runs, a second controller on the same journal reports the task INTERRUPTED and starts nothing;
// `riggerctl resume` rebuilds it from the journal and asks the operator (prompt kind "resume"); only the
// operator's answer starts anything. Real task_controller, scripted executor and riggerctl processes.
// RelocalizeTest adds the real world_model: a load localized before the crash and moved (a new
// observation) while the controller was down is localized again before anything else runs.
#include <algorithm>
#include <functional>
#include <map>
#include <string>

#include <gtest/gtest.h>
#include <Eigen/Geometry>

#include "controller_test_support.hpp"
#include "rigger/base/logging.hpp"
#include "rigger/world_client/world_client.hpp"

namespace rigger::testing::controller {
namespace {

json skill(const std::string& name, const std::string& object) {
  return {{"type", "Skill"}, {"name", name}, {"skill", "Localize"}, {"params", {{"object", object}}}};
}

class ResumeTest : public ControllerTest {
 protected:
  /// Task `task_id`, Sequence [first (load), second (target), third (target)]; tc is killed while
  /// `second` (2 s) runs, tc-2 is started on the same journal and has reported the task INTERRUPTED when
  /// this returns. What runs after the crash uses the target only, so the load's completed localization
  /// is no precondition of it and no world model is asked (RelocalizeTest is about that).
  /// `while_down` runs before tc-2 starts, `tc2_config` adds to tc-2's configuration.
  void crash_in_the_second_skill(const std::string& task_id, bool second_restartable = false,
                                 const std::function<void()>& while_down = {},
                                 const json& tc2_config = json::object()) {
    expect_clean_exit_ = false;  // tc is killed
    start_controller();
    start_scripted("exec", {"Localize"},
                   {{"root/0", {{"mode", "succeed"}, {"delay_s", 0.1}}},
                    {"root/1", {{"mode", "succeed"}, {"delay_s", 2.0}}},
                    {"root/2", {{"mode", "succeed"}, {"delay_s", 0.1}}}});
    wait_ready({"tc", "exec"});
    json second = skill("second", "target");
    if (second_restartable) second["restartable"] = true;
    submit(
        task_id,
        {{"recipe_version", 1},
         {"task_id", task_id},
         {"root", {{"type", "Sequence"}, {"children", {skill("first", "load"), second, skill("third", "target")}}}}});
    ASSERT_TRUE(cell_.wait_until([&] { return event_at(task_id, "root/1", rigger_skill_SKILL_EVENT_ACCEPTED); }, 20s));
    // Killed once the journal holds the second START: the rows of a handler are written right after its
    // commands, so a kill just after a START may lose them (then the first skill counts as interrupted,
    // and the operator decides about it too; ResumePlan.* covers that case).
    ASSERT_TRUE(cell_.wait_until([&] { return has_line(journal(task_id), "root/1", "COMMAND", "START"); }, 10s));
    cell_.loop().on_status(recipes_->handle(), DDS_PUBLICATION_MATCHED_STATUS, [] {});
    ASSERT_TRUE(cell_.stop("tc", SIGKILL, 5s).has_value());
    ASSERT_TRUE(cell_.wait_until([&] { return recipes_->matched_readers() == 0; }, 10s));
    starts_before_ = count_commands(task_id, rigger_skill_SKILL_START);
    if (while_down) while_down();
    start_controller(tc2_config, "tc-2");
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

// A RESUME that comes before the restarted controller has heard the executors (here: the executor is
// down, and comes back later) waits for them, as a new recipe does, instead of calling the recipe no
// longer valid for its unknown skills.
TEST_F(ResumeTest, AResumeBeforeTheExecutorsAreHeardWaitsForThem) {
  crash_in_the_second_skill(
      "early", false, [&] { ASSERT_TRUE(cell_.stop("exec", SIGINT, 10s).has_value()); },
      {{"executor_wait_s", 20}});
  command("early", rigger_task_TASK_RESUME, "right after the restart");
  // It waits: no refusal, no prompt, while no executor offers Localize.
  EXPECT_FALSE(cell_.wait_until([&] { return code_seen("early", "RESUME_REFUSED") || prompt("early", "resume"); },
                                1s))
      << "the resume did not wait for the executors";
  // The executor "exec" back (a process of another name: the harness names each process once).
  const json again = {{"skills", {"Localize"}},
                      {"nodes",
                       {{"root/1", {{"mode", "succeed"}, {"delay_s", 0.1}}},
                        {"root/2", {{"mode", "succeed"}, {"delay_s", 0.1}}}}}};
  cell_.start("exec-again", "scripted_executor", {"--id", "exec", "--config", write_config("exec-again", again)});
  const PromptSeen* p = resume_prompt("early");
  ASSERT_NE(p, nullptr) << "no resume prompt once the executor was heard";
  EXPECT_FALSE(code_seen("early", "RESUME_REFUSED"));
  const auto lines = journal("early");
  EXPECT_EQ(std::count_if(lines.begin(), lines.end(),
                          [](const JournalLine& l) { return l.kind == "COMMAND" && l.code == "RESUME"; }),
            1)
      << "the waiting resume is journaled once, when it goes on";
  answer("early#resume#1", "rerun");
  ASSERT_TRUE(wait_finished("early", 30s));
  EXPECT_EQ(last("early").state, rigger_task_TASK_SUCCEEDED) << last("early").code << " " << last("early").message;
}

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

/// With the real world model: Sequence [Localize(load) "localize load", Localize(target) "second" (2 s),
/// Pick(load) "pick load"]. The camera's observation of the load (written by the test, as the tracker
/// would) is in the world model before the task starts; the controller journals the load's pose when
/// "localize load" succeeds and is killed while "second" runs.
class RelocalizeTest : public ResumeTest {
 protected:
  void SetUp() override {
    ResumeTest::SetUp();
    cell_.start("wm", "world_model", {"--id", "wm", "--db", cell_.log_dir() + "/world.sqlite"});
    world_ = std::make_unique<world_client::WorldClient>(cell_.participant(), cell_.loop(), null_logger(), "test");
  }

  /// An observation of the load at `pose` (world frame), stamped now, as the tracker would write it.
  void see_load(const Eigen::Vector3d& position) {
    Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
    pose.translation() = position;
    std::optional<world_client::Reply> updated;
    world_->update_pose("load", "world", pose, std::chrono::system_clock::now(), 0.9, true, 5s,
                        [&](const world_client::Reply& r) { updated = r; });
    ASSERT_TRUE(cell_.wait_until([&] { return updated.has_value(); }, 10s));
    ASSERT_TRUE(updated->ok) << updated->code << ": " << updated->message;
  }

  /// Runs the task until the controller is killed in "second"; `while_down` runs before tc-2 starts.
  void crash_after_localizing_the_load(const std::string& task_id, const std::function<void()>& while_down) {
    expect_clean_exit_ = false;  // tc is killed
    start_controller();
    start_scripted("exec", {"Localize", "Pick"},
                   {{"root/0", {{"mode", "succeed"}, {"delay_s", 0.1}}},
                    {"root/1", {{"mode", "succeed"}, {"delay_s", 2.0}}},
                    {"root/2", {{"mode", "succeed"}, {"delay_s", 0.1}}}});
    wait_ready({"wm", "tc", "exec"});
    ASSERT_TRUE(cell_.wait_until([&] { return world_->connected(); }, 10s));
    see_load(kLoadAt);
    const json pick = {{"type", "Skill"},
                       {"name", "pick load"},
                       {"skill", "Pick"},
                       {"params", {{"object", "load"}, {"grasp", "load/grasp_side"}}}};
    const json children = {skill("localize load", "load"), skill("second", "target"), pick};
    submit(task_id,
           {{"recipe_version", 1}, {"task_id", task_id}, {"root", {{"type", "Sequence"}, {"children", children}}}});
    ASSERT_TRUE(cell_.wait_until([&] { return event_at(task_id, "root/1", rigger_skill_SKILL_EVENT_ACCEPTED); }, 20s));
    // The load's pose is journaled (the world model answered) and the second START is in the journal.
    ASSERT_TRUE(cell_.wait_until(
        [&] {
          const auto lines = journal(task_id);
          return has_line(lines, "root/0", "WORLD", "LOCALIZED") && has_line(lines, "root/1", "COMMAND", "START");
        },
        10s));
    cell_.loop().on_status(recipes_->handle(), DDS_PUBLICATION_MATCHED_STATUS, [] {});
    ASSERT_TRUE(cell_.stop("tc", SIGKILL, 5s).has_value());
    ASSERT_TRUE(cell_.wait_until([&] { return recipes_->matched_readers() == 0; }, 10s));
    starts_before_ = count_commands(task_id, rigger_skill_SKILL_START);
    while_down();
    start_controller(json::object(), "tc-2");
    wait_ready({"tc-2"});
    ASSERT_TRUE(cell_.wait_until([&] { return code_seen(task_id, "INTERRUPTED"); }, 10s));
  }

  /// details_json of the open resume prompt of `task_id`.
  json resume_details(const std::string& task_id) {
    const PromptSeen* p = resume_prompt(task_id);
    if (p == nullptr) return json();
    return json::parse(p->details_json, nullptr, false);
  }

  /// The operator reruns the interrupted "second"; the task must succeed.
  void rerun_to_success(const std::string& task_id) {
    answer(task_id + "#resume#1", "rerun");
    ASSERT_TRUE(wait_finished(task_id, 30s));
    EXPECT_EQ(last(task_id).state, rigger_task_TASK_SUCCEEDED) << last(task_id).code << " " << last(task_id).message;
  }

  const Eigen::Vector3d kLoadAt{3.4, 1.8, 1.25};
  std::unique_ptr<world_client::WorldClient> world_;
};

TEST_F(RelocalizeTest, ALoadMovedWhileTheControllerWasDownIsLocalizedAgainFirstAndTheTaskSucceeds) {
  crash_after_localizing_the_load("moved", [&] { see_load(kLoadAt + Eigen::Vector3d(0.045, 0, 0)); });
  const CtlResult r = ctl("resume", {"resume", "moved"});
  EXPECT_EQ(r.code(), 0) << r.output;
  std::printf("riggerctl resume:\n%s", r.output.c_str());
  EXPECT_NE(r.output.find("load moved 45 mm and 0.0 deg since it was localized at "), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("Localize(load) (root/0, localize load) will run again (preconditions do not hold)"),
            std::string::npos)
      << r.output;
  EXPECT_NE(r.output.find("runs again): root/0 (localize load)"), std::string::npos) << r.output;
  const json d = resume_details("moved");
  ASSERT_TRUE(d.is_object()) << "no resume prompt with details";
  EXPECT_EQ(d["relocalize"], json::array({"root/0"}));
  EXPECT_EQ(d["done"], json::array());
  ASSERT_EQ(d["world"].size(), 1U) << d.dump();
  const json& load = d["world"][0];
  EXPECT_EQ(load["object"], "load");
  EXPECT_EQ(load["verdict"], "moved");
  EXPECT_EQ(load["relocalize"], true);
  EXPECT_EQ(load["preconditions_hold"], false);
  EXPECT_EQ(load["world_model"], "answered");
  EXPECT_NEAR(load["displacement_mm"].get<double>(), 45.0, 0.5);
  EXPECT_EQ(load["used_by"], json::array({"root/2"}));
  EXPECT_LT(load["pose_age_s"].get<double>(), 60.0);
  EXPECT_EQ(count_commands("moved", rigger_skill_SKILL_START), starts_before_) << "nothing before the confirmation";

  rerun_to_success("moved");
  // The moved load's localization ran again (first), the interrupted skill by the operator's rerun.
  EXPECT_EQ(journaled_starts("moved"), (std::map<std::string, int>{{"root/0", 2}, {"root/1", 2}, {"root/2", 1}}));
  int poses = 0;
  for (const auto& l : journal("moved")) poses += l.node == "root/0" && l.kind == "WORLD" && l.code == "LOCALIZED";
  EXPECT_EQ(poses, 2) << "each localization journals the load's pose";
}

TEST_F(RelocalizeTest, ALoadThatDidNotMoveStaysLocalizedAndEachCompletedSkillRunsOnce) {
  // A new observation 2 mm off (camera noise) is no move.
  crash_after_localizing_the_load("still", [&] { see_load(kLoadAt + Eigen::Vector3d(0, 0.002, 0)); });
  const CtlResult r = ctl("resume", {"resume", "still"});
  EXPECT_EQ(r.code(), 0) << r.output;
  EXPECT_NE(r.output.find("done, not run again: root/0 (localize load)"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("load is where it was localized (2 mm and 0.0 deg off since it was localized at "),
            std::string::npos)
      << r.output;
  EXPECT_NE(r.output.find("its localization stays done (preconditions hold)"), std::string::npos) << r.output;
  const json d = resume_details("still");
  ASSERT_TRUE(d.is_object());
  EXPECT_EQ(d["relocalize"], json::array());
  ASSERT_EQ(d["world"].size(), 1U) << d.dump();
  EXPECT_EQ(d["world"][0]["verdict"], "unchanged");
  EXPECT_EQ(d["world"][0]["preconditions_hold"], true);
  EXPECT_EQ(d["world"][0]["localized"], true);
  rerun_to_success("still");
  EXPECT_EQ(journaled_starts("still"), (std::map<std::string, int>{{"root/0", 1}, {"root/1", 2}, {"root/2", 1}}));
}

// Nothing looked at the load while the controller was down (the tracker is idle unless a skill asks it):
// the world model's pose is the one the localization saw, which says nothing of where the load is now.
TEST_F(RelocalizeTest, ALoadNobodySawSinceTheCrashIsLocalizedAgain) {
  crash_after_localizing_the_load("unseen", [] {});
  const CtlResult r = ctl("resume", {"resume", "unseen"});
  EXPECT_EQ(r.code(), 0) << r.output;
  EXPECT_NE(r.output.find("nothing has seen load since the controller stopped"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("it may have been moved; Localize(load) (root/0, localize load) will run again"),
            std::string::npos)
      << r.output;
  const json d = resume_details("unseen");
  ASSERT_TRUE(d.is_object()) << "no resume prompt with details";
  EXPECT_EQ(d["relocalize"], json::array({"root/0"}));
  ASSERT_EQ(d["world"].size(), 1U) << d.dump();
  EXPECT_EQ(d["world"][0]["verdict"], "unconfirmed");
  EXPECT_EQ(d["world"][0]["preconditions_hold"], false);
  EXPECT_NEAR(d["world"][0]["displacement_mm"].get<double>(), 0.0, 0.5) << "the same pose: no evidence either way";
  rerun_to_success("unseen");
  EXPECT_EQ(journaled_starts("unseen"), (std::map<std::string, int>{{"root/0", 2}, {"root/1", 2}, {"root/2", 1}}));
}

TEST_F(RelocalizeTest, AWorldModelThatIsDownIsSaidInThePromptAndTheLoadIsLocalizedAgain) {
  crash_after_localizing_the_load("blind", [&] { ASSERT_TRUE(cell_.stop("wm", SIGINT, 10s).has_value()); });
  const CtlResult r = ctl("resume", {"resume", "blind"});
  EXPECT_EQ(r.code(), 0) << r.output;
  EXPECT_NE(r.output.find("the world model did not answer about load (WORLD_UNREACHABLE"), std::string::npos)
      << r.output;
  EXPECT_NE(r.output.find("will run again to be safe"), std::string::npos) << r.output;
  const json d = resume_details("blind");
  ASSERT_TRUE(d.is_object());
  EXPECT_EQ(d["relocalize"], json::array({"root/0"}));
  ASSERT_EQ(d["world"].size(), 1U) << d.dump();
  EXPECT_EQ(d["world"][0]["verdict"], "unknown");
  EXPECT_EQ(d["world"][0]["world_model"].get<std::string>().rfind("WORLD_UNREACHABLE", 0), 0U) << d.dump();
  rerun_to_success("blind");
  EXPECT_EQ(journaled_starts("blind"), (std::map<std::string, int>{{"root/0", 2}, {"root/1", 2}, {"root/2", 1}}));
}

}  // namespace
}  // namespace rigger::testing::controller
