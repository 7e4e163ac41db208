// The task lifecycle through the controller as a real process, against scripted executors:
// PAUSE/RESUME (docs/behavior-tree.md rule 7), CANCEL (rule 8), OperatorDecision over
// rigger/operator/prompt|response, and the stop-timeout escalation (rule 3).
#include <map>
#include <string>

#include <gtest/gtest.h>

#include "controller_test_support.hpp"
#include "rigger/dds/liveliness.hpp"
#include "rigger/safety/safe_stop.hpp"

namespace rigger::testing::controller {
namespace {

json skill(const std::string& name, const std::string& object) {
  return {{"type", "Skill"}, {"name", name}, {"skill", "Localize"}, {"params", {{"object", object}}}};
}
json recipe(const std::string& task_id, const json& root) {
  return {{"recipe_version", 1}, {"task_id", task_id}, {"root", root}};
}

class LifecycleTest : public ControllerTest {
 protected:
  void start_cell(const json& nodes, const json& behaviours = json::object()) {
    start_controller();
    start_scripted("exec", {"Localize", "TimerMonitor", "YankMonitor"}, nodes, behaviours);
    wait_ready({"tc", "exec"});
  }
};

TEST_F(LifecycleTest, PauseLetsTheRunningLeafFinishButStartsNothingNewUntilResume) {
  start_cell(
      {{"root/0", {{"mode", "succeed"}, {"delay_s", 0.5}}}, {"root/1", {{"mode", "succeed"}, {"delay_s", 0.1}}}});
  submit("pause",
         recipe("pause", {{"type", "Sequence"}, {"children", {skill("first", "load"), skill("second", "target")}}}));
  ASSERT_TRUE(wait_command("pause", "root/0", rigger_skill_SKILL_START));
  command("pause", rigger_task_TASK_PAUSE, "crane operator needs a minute");
  ASSERT_TRUE(wait_task("pause", rigger_task_TASK_PAUSED));
  EXPECT_EQ(task_at("pause", rigger_task_TASK_PAUSED)->message, "crane operator needs a minute");
  // The running leaf is not stopped: it finishes, and its SUCCESS is taken.
  ASSERT_TRUE(wait_node("pause", "root/0", rigger_task_NODE_SUCCESS));
  EXPECT_EQ(command_at("pause", "root/0", rigger_skill_SKILL_SHUTDOWN), nullptr);
  // The journal (answered after the controller handled that SUCCESS) shows the next START held back.
  const auto held = journal("pause");
  EXPECT_TRUE(has_line(held, "", "COMMAND", "PAUSE"));
  EXPECT_TRUE(has_line(held, "root/0", "EVENT", "SUCCESS"));
  EXPECT_FALSE(has_line(held, "root/1", "COMMAND", "START"));
  EXPECT_EQ(command_at("pause", "root/1", rigger_skill_SKILL_START), nullptr);
  EXPECT_FALSE(finished("pause"));
  // A second PAUSE is refused and journalled as such; the task stays paused.
  command("pause", rigger_task_TASK_PAUSE, "again");
  ASSERT_TRUE(cell_.wait_until(
      [&] {
        const auto lines = journal("pause");
        return has_line(lines, "", "REJECTED_EVENT", "WRONG_PHASE");
      },
      10s));

  const auto resumed_at = Clock::now();
  command("pause", rigger_task_TASK_RESUME, "go on");
  ASSERT_TRUE(wait_command("pause", "root/1", rigger_skill_SKILL_START));
  EXPECT_GE(command_at("pause", "root/1", rigger_skill_SKILL_START)->at, resumed_at);
  ASSERT_TRUE(wait_finished("pause"));
  EXPECT_EQ(last("pause").state, rigger_task_TASK_SUCCEEDED) << last("pause").code << " " << last("pause").message;
  // PAUSED then RUNNING again, in that order.
  const TaskSeen* paused = task_at("pause", rigger_task_TASK_PAUSED);
  bool running_after_pause = false;
  for (const auto& s : tasks_["pause"])
    if (s.state == rigger_task_TASK_RUNNING && s.at > paused->at) running_after_pause = true;
  EXPECT_TRUE(running_after_pause);
}

// A leaf that cannot pause but holds devices (the scripted executor pauses nothing; Pick holds robot and
// gripper) is brought to its safe stop by the PAUSE: riggerctl pause prints that, the leaf
// fails NOT_PAUSABLE ("could not pause"), the Sequence above it fails, and the task ends FAILED with it.
TEST_F(LifecycleTest, APauseStopsALeafThatCannotPauseButHoldsDevicesAndItsNodeReportsIt) {
  start_controller();
  start_scripted("exec", {"Localize", "Pick"},
                 {{"root/0", {{"mode", "succeed"}, {"delay_s", 0.05}}},
                  {"root/1", {{"mode", "run"}, {"stop_delay_s", 0.2}}}});
  wait_ready({"tc", "exec"});
  const json pick = {{"type", "Skill"},
                     {"name", "grab"},
                     {"skill", "Pick"},
                     {"params", {{"object", "load"}, {"grasp", "load/grasp_top"}}}};
  submit("np", recipe("np", {{"type", "Sequence"}, {"children", {skill("find", "load"), pick}}}));
  ASSERT_TRUE(cell_.wait_until([&] { return event_at("np", "root/1", rigger_skill_SKILL_EVENT_ACCEPTED); }, 20s));
  const auto paused = ctl("pause", {"pause", "np", "--reason", "hold"});
  EXPECT_EQ(paused.code(), 0) << paused.output;
  EXPECT_NE(paused.output.find("root/1: NOT_PAUSABLE_STOPPED: Pick cannot pause and holds robot, gripper: it is "
                               "brought to its safe stop"),
            std::string::npos)
      << paused.output;
  ASSERT_TRUE(wait_node("np", "root/1", rigger_task_NODE_FAILURE));
  EXPECT_EQ(node_at("np", "root/1", rigger_task_NODE_FAILURE)->code, "NOT_PAUSABLE");
  ASSERT_TRUE(wait_finished("np"));
  EXPECT_EQ(last("np").state, rigger_task_TASK_FAILED);
  EXPECT_EQ(last("np").code, "NOT_PAUSABLE") << last("np").message;
  EXPECT_EQ(command_at("np", "root/1", rigger_skill_SKILL_SHUTDOWN), nullptr) << "the executor stopped it, not a SHUTDOWN";
  const auto lines = journal("np");
  EXPECT_TRUE(has_line(lines, "root/1", "EVENT", "NOT_PAUSED"));
  EXPECT_TRUE(has_line(lines, "root/1", "EVENT", "FAILURE"));
}

TEST_F(LifecycleTest, CancelWhilePausedStopsTheRunningLeafAndDropsTheHeldStart) {
  start_cell({{"root/0", {{"mode", "run"}, {"stop_delay_s", 0.1}}}});
  submit("pc", recipe("pc", {{"type", "Sequence"}, {"children", {skill("first", "load"), skill("second", "target")}}}));
  ASSERT_TRUE(wait_command("pc", "root/0", rigger_skill_SKILL_START));
  command("pc", rigger_task_TASK_PAUSE, "hold");
  ASSERT_TRUE(wait_task("pc", rigger_task_TASK_PAUSED));
  command("pc", rigger_task_TASK_CANCEL, "never mind");
  ASSERT_TRUE(wait_finished("pc"));
  EXPECT_EQ(last("pc").state, rigger_task_TASK_CANCELED);
  EXPECT_NE(command_at("pc", "root/0", rigger_skill_SKILL_SHUTDOWN), nullptr);
  EXPECT_NE(node_at("pc", "root/0", rigger_task_NODE_STOPPED), nullptr);
  EXPECT_EQ(command_at("pc", "root/1", rigger_skill_SKILL_START), nullptr);
}

TEST_F(LifecycleTest, CancelShutsEveryRunningLeafDownAndEndsCanceledAfterAllStopped) {
  start_cell({{"root/0", {{"mode", "run"}, {"stop_delay_s", 0.3}}}});
  const json root = {{"type", "Parallel"},
                     {"success_threshold", 1},
                     {"failure_threshold", 1},
                     {"children",
                      {skill("localize", "load"),
                       {{"type", "Monitor"}, {"monitor", "TimerMonitor"}, {"params", {{"max_duration_s", 600}}}},
                       {{"type", "Monitor"}, {"monitor", "YankMonitor"}}}}};
  submit("cancel", recipe("cancel", root));
  ASSERT_TRUE(cell_.wait_until([&] { return count_commands("cancel", rigger_skill_SKILL_START) == 3; }, 20s));
  command("cancel", rigger_task_TASK_CANCEL, "load swinging");
  ASSERT_TRUE(wait_finished("cancel"));
  const TaskSeen& s = last("cancel");
  EXPECT_EQ(s.state, rigger_task_TASK_CANCELED);
  EXPECT_EQ(s.code, "CANCELED");
  EXPECT_NE(s.message.find("load swinging"), std::string::npos) << s.message;
  // Every running leaf got SHUTDOWN and answered STOPPED before the task reported CANCELED.
  for (const char* node : {"root/0", "root/1", "root/2"}) {
    EXPECT_NE(command_at("cancel", node, rigger_skill_SKILL_SHUTDOWN), nullptr) << node;
    const EventSeen* stopped = event_at("cancel", node, rigger_skill_SKILL_EVENT_STOPPED);
    ASSERT_NE(stopped, nullptr) << node;
    EXPECT_LE(stopped->at, s.at) << node;
    const NodeSeen* n = node_at("cancel", node, rigger_task_NODE_STOPPED);
    ASSERT_NE(n, nullptr) << node;
    EXPECT_TRUE(n->code.empty()) << node << ": " << n->code;  // a clean stop, not a timeout
  }
  EXPECT_NE(node_at("cancel", "root", rigger_task_NODE_STOPPED), nullptr);
  const auto lines = journal("cancel");
  EXPECT_TRUE(has_line(lines, "", "COMMAND", "CANCEL"));
  EXPECT_TRUE(has_line(lines, "root/0", "EVENT", "STOPPED"));
  // A command for a task that has ended changes nothing.
  command("cancel", rigger_task_TASK_RESUME, "too late");
  EXPECT_EQ(last("cancel").state, rigger_task_TASK_CANCELED);
}

/// OperatorDecision at the root: "joystick" → root/0 (Localize load), "abort" → root/1 (Localize target).
json decision(const std::string& task_id) {
  return recipe(task_id, {{"type", "OperatorDecision"},
                          {"name", "how"},
                          {"prompt", "How should the load be brought to the target?"},
                          {"options",
                           {{{"label", "joystick"}, {"child", skill("by hand", "load")}},
                            {{"label", "abort"}, {"child", skill("give up", "target")}}}}});
}

TEST_F(LifecycleTest, OperatorDecisionTakesTheBranchOfEachAnswer) {
  start_cell({{"root/1", {{"mode", "fail"}, {"delay_s", 0.1}, {"code", "ABANDONED"}}}});
  for (const auto& [task, choice, taken, other] :
       {std::tuple<std::string, std::string, std::string, std::string>{"op-joystick", "joystick", "root/0", "root/1"},
        {"op-abort", "abort", "root/1", "root/0"}}) {
    submit(task, decision(task));
    ASSERT_TRUE(cell_.wait_until(
        [&, task = task] {
          const PromptSeen* p = prompt(task, "root");
          return p != nullptr && p->active;
        },
        20s))
        << task;
    const PromptSeen* asked = prompt(task, "root");
    EXPECT_EQ(asked->text, "How should the load be brought to the target?");
    EXPECT_EQ(asked->options, (std::vector<std::string>{"joystick", "abort"}));
    EXPECT_EQ(count_commands(task, rigger_skill_SKILL_START), 0U) << "nothing starts before the answer";
    // An answer that is not an option is journalled as rejected and changes nothing.
    answer(asked->prompt_id, "sideways");
    ASSERT_TRUE(cell_.wait_until(
        [&, task = task] { return has_line(journal(task), "root", "REJECTED_EVENT", "NOT_AN_OPTION"); }, 10s))
        << task;
    EXPECT_EQ(count_commands(task, rigger_skill_SKILL_START), 0U);
    answer(asked->prompt_id, choice);
    ASSERT_TRUE(wait_finished(task)) << task;
    EXPECT_NE(command_at(task, taken, rigger_skill_SKILL_START), nullptr) << task;
    EXPECT_EQ(command_at(task, other, rigger_skill_SKILL_START), nullptr) << task;
    // Once answered, the prompt is withdrawn so that no UI keeps asking.
    ASSERT_TRUE(cell_.wait_until([&, task = task] { return !prompt(task, "root")->active; }, 10s)) << task;
    const auto lines = journal(task);
    EXPECT_TRUE(has_line(lines, "root", "OPERATOR", "ASK")) << task;
    EXPECT_TRUE(has_line(lines, "root", "OPERATOR", "ANSWER")) << task;
  }
  EXPECT_EQ(last("op-joystick").state, rigger_task_TASK_SUCCEEDED);
  EXPECT_EQ(last("op-abort").state, rigger_task_TASK_FAILED);
  EXPECT_EQ(last("op-abort").code, "ABANDONED");
  EXPECT_EQ(last("op-abort").failed_node, "root/1");
}

TEST_F(LifecycleTest, CancelWithdrawsAnOpenPromptAndALateAnswerIsIgnored) {
  start_cell(json::object());
  submit("op-cancel", decision("op-cancel"));
  ASSERT_TRUE(cell_.wait_until(
      [&] {
        const PromptSeen* p = prompt("op-cancel", "root");
        return p != nullptr && p->active;
      },
      20s));
  const std::string prompt_id = prompt("op-cancel", "root")->prompt_id;
  command("op-cancel", rigger_task_TASK_CANCEL, "shift over");
  ASSERT_TRUE(wait_finished("op-cancel"));
  EXPECT_EQ(last("op-cancel").state, rigger_task_TASK_CANCELED);
  ASSERT_TRUE(cell_.wait_until([&] { return !prompt("op-cancel", "root")->active; }, 10s));
  EXPECT_EQ(prompt("op-cancel", "root")->prompt_id, prompt_id);
  answer(prompt_id, "joystick");
  // The answer arrives at a task that no longer asks: journalled as rejected, nothing starts.
  ASSERT_TRUE(
      cell_.wait_until([&] { return has_line(journal("op-cancel"), "root", "REJECTED_EVENT", "NOT_ASKED"); }, 10s));
  EXPECT_EQ(count_commands("op-cancel", rigger_skill_SKILL_START), 0U);
}

TEST_F(LifecycleTest, ASkillThatNeverAnswersStoppedIsEscalatedAfterItsStopTimeout) {
  start_cell({{"root/0", {{"mode", "run"}, {"never_stop", true}}},
              {"root/1", {{"mode", "fail"}, {"delay_s", 0.2}, {"code", "YANK_DETECTED"}}}});
  const json root = {{"type", "Parallel"},
                     {"success_threshold", 1},
                     {"failure_threshold", 1},
                     {"stop_timeout_s", 0.5},
                     {"children", {skill("hold on", "load"), {{"type", "Monitor"}, {"monitor", "YankMonitor"}}}}};
  submit("hung", recipe("hung", root));
  ASSERT_TRUE(wait_finished("hung"));
  const TaskSeen& s = last("hung");
  // The Parallel reports the monitor's failure, but only after the skill's stop timeout passed.
  EXPECT_EQ(s.state, rigger_task_TASK_FAILED);
  EXPECT_EQ(s.code, "YANK_DETECTED");
  EXPECT_EQ(s.failed_node, "root/1");
  EXPECT_NE(s.message.find("safe stop escalated: root/0"), std::string::npos) << s.message;
  const CommandSeen* shutdown = command_at("hung", "root/0", rigger_skill_SKILL_SHUTDOWN);
  ASSERT_NE(shutdown, nullptr);
  EXPECT_EQ(event_at("hung", "root/0", rigger_skill_SKILL_EVENT_STOPPED), nullptr);
  const NodeSeen* timed_out = node_at("hung", "root/0", rigger_task_NODE_STOPPED);
  ASSERT_NE(timed_out, nullptr);
  EXPECT_EQ(timed_out->code, "STOP_TIMEOUT");
  EXPECT_NE(timed_out->message.find("did not acknowledge SHUTDOWN within 0.5 s"), std::string::npos)
      << timed_out->message;
  const NodeSeen* parallel = node_at("hung", "root", rigger_task_NODE_FAILURE);
  ASSERT_NE(parallel, nullptr);
  EXPECT_LE(timed_out->at, parallel->at);
  // The SHUTDOWN (and its 0.5 s stop timer) went out in the same turn that published the monitor's
  // FAILURE, so the Parallel's report follows that FAILURE by the stop timeout (less delivery jitter).
  const NodeSeen* fired = node_at("hung", "root/1", rigger_task_NODE_FAILURE);
  ASSERT_NE(fired, nullptr);
  EXPECT_GE(parallel->at - fired->at, 400ms) << "the Parallel reported before the stop timeout";
  // The journal names the escalation with the resources of the leaf.
  const auto lines = journal("hung");
  bool escalation = false;
  for (const auto& l : lines)
    if (l.node == "root/0" && l.kind == "ESCALATION" && l.code == "SAFE_STOP" &&
        l.message.find("camera") != std::string::npos)
      escalation = true;
  EXPECT_TRUE(escalation);
}

// Every START gets an answer: a real executor answers ACCEPTED before its skill's first
// event. An executor that announces a skill but never answers (a lost sample, a wedged executor whose
// lease is still asserted) must not leave the task RUNNING forever: after start_answer_timeout_s the
// controller fails the leaf START_UNANSWERED, sends a SHUTDOWN after the START, and the task goes on.
TEST_F(LifecycleTest, AStartNobodyAnswersFailsItsLeafInsteadOfHangingTheTask) {
  start_controller({{"start_answer_timeout_s", 0.5}});
  start_scripted("exec", {"Localize"}, {{"root/1", {{"mode", "succeed"}, {"delay_s", 0.1}}}});
  wait_ready({"tc", "exec"});
  // "mute" offers Deaf (exec's description of Localize, renamed: admission then waits until the
  // controller knows mute), asserts its lease, and answers nothing.
  auto& p = cell_.participant();
  dds::Reader<rigger_skill_ExecutorAnnouncement> announced(p, protocol::skill::kExecutors);
  json library;
  ASSERT_TRUE(cell_.wait_until(
      [&] {
        announced.take([&](const rigger_skill_ExecutorAnnouncement& a, const dds_sample_info_t& info) {
          if (info.valid_data && dds::to_string(a.executor_id) == "exec")
            library = json::parse(dds::to_string(a.library_json));
        });
        return !library.is_null();
      },
      10s));
  json deaf;
  for (const auto& d : library.at("skills"))
    if (d.value("name", "") == "Localize") deaf = d;
  ASSERT_FALSE(deaf.is_null()) << library.dump();
  deaf["name"] = "Deaf";
  const std::string deaf_library = json{{"library_version", 1}, {"skills", {deaf}}}.dump();
  dds::Writer<rigger_skill_ExecutorAnnouncement> mute(p, protocol::skill::kExecutors);
  auto lease = std::make_unique<dds::LivelinessAsserter>(p, dds::liveliness_lease() / 3, 0ms);
  rigger_skill_ExecutorAnnouncement a{};
  const std::string id = "mute", host = "test";
  const std::vector<std::string> skills = {"Deaf"};
  std::vector<char*> names;
  a.executor_id = dds::wire_string(id);
  a.host = dds::wire_string(host);
  a.pid = 0;
  dds::wire_string_sequence(a.skills, skills, names);
  a.library_json = dds::wire_string(deaf_library);
  a.stamp = dds::wire_now();
  ASSERT_EQ(mute.write(a), DDS_RETCODE_OK);

  json unanswered = skill("deaf", "load");
  unanswered["skill"] = "Deaf";
  const auto submitted = Clock::now();
  submit("deaf", recipe("deaf", {{"type", "Fallback"}, {"children", {unanswered, skill("heard", "target")}}}));
  ASSERT_TRUE(wait_finished("deaf")) << cell_.logs();
  lease.reset();
  EXPECT_EQ(last("deaf").state, rigger_task_TASK_SUCCEEDED) << last("deaf").message;

  const CommandSeen* start = command_at("deaf", "root/0", rigger_skill_SKILL_START);
  ASSERT_NE(start, nullptr);
  EXPECT_EQ(start->executor, "mute");
  const NodeSeen* failed = node_at("deaf", "root/0", rigger_task_NODE_FAILURE);
  ASSERT_NE(failed, nullptr);
  EXPECT_EQ(failed->code, "START_UNANSWERED");
  EXPECT_NE(failed->message.find("got no answer from mute within 0.5 s"), std::string::npos) << failed->message;
  // Measured from the submission: the first START this test's reader sees can be one sent again 0.2 s
  // after the first, which a reader that had just matched the writer dropped (docs/dds.md).
  EXPECT_GE(failed->at - submitted, 500ms) << "failed before the answer timeout";
  EXPECT_GE(sent_again_, 1u) << "the unanswered START was not sent again, with its seq";
  EXPECT_TRUE(has_line(journal("deaf"), "root/0", "COMMAND", "START_SENT_AGAIN"));
  // The SHUTDOWN follows the START, so a START delivered late is stopped at once.
  const CommandSeen* shutdown = command_at("deaf", "root/0", rigger_skill_SKILL_SHUTDOWN);
  ASSERT_NE(shutdown, nullptr);
  EXPECT_GT(shutdown->seq, start->seq);
  // exec answered its START before its skill's SUCCESS.
  const EventSeen* accepted = event_at("deaf", "root/1", rigger_skill_SKILL_EVENT_ACCEPTED);
  const EventSeen* success = event_at("deaf", "root/1", rigger_skill_SKILL_EVENT_SUCCESS);
  ASSERT_NE(accepted, nullptr);
  ASSERT_NE(success, nullptr);
  EXPECT_LE(accepted->at, success->at);
  bool journaled = false;
  for (const auto& l : journal("deaf"))
    if (l.node == "root/0" && l.kind == "EVENT" && l.code == "FAILURE" &&
        l.message.rfind("START_UNANSWERED", 0) == 0)
      journaled = true;
  EXPECT_TRUE(journaled);
}

// The same escalation for a skill that holds devices: the controller commands the safe stop of the
// robot and the gripper it held (rigger/safety/stop), which the devices obey (tested in physics in
// safe_stop_cell_test), and journals what it commanded.
TEST_F(LifecycleTest, AnEscalatedStopCommandsTheSafeStopOfTheDevicesTheLeafHeld) {
  start_controller();
  start_scripted("exec", {"Localize", "Pick", "YankMonitor"},
                 {{"root/0", {{"mode", "succeed"}, {"delay_s", 0.05}}},
                  {"root/1/0", {{"mode", "run"}, {"never_stop", true}}},
                  {"root/1/1", {{"mode", "fail"}, {"delay_s", 0.2}, {"code", "YANK_DETECTED"}}}});
  wait_ready({"tc", "exec"});
  std::map<std::string, safety::StopState> stops;
  safety::SafeStopListener devices(cell_.participant(), cell_.loop(), safety::stoppable_resources(),
                                   [&](const std::string& r, const safety::StopState& st) { stops[r] = st; });
  const json grab = {{"type", "Parallel"},
                     {"success_threshold", 1},
                     {"failure_threshold", 1},
                     {"stop_timeout_s", 0.5},
                     {"children",
                      {{{"type", "Skill"},
                        {"name", "grab"},
                        {"skill", "Pick"},
                        {"params", {{"object", "load"}, {"grasp", "load/grasp_top"}}}},
                       {{"type", "Monitor"}, {"monitor", "YankMonitor"}, {"params", {{"max_yank_n_per_s", 400}}}}}}};
  const json root = {{"type", "Sequence"}, {"children", {skill("find", "load"), grab}}};
  submit("hung-robot", recipe("hung-robot", root));
  ASSERT_TRUE(wait_finished("hung-robot"));
  ASSERT_TRUE(cell_.wait_until([&] { return stops.size() == 2; }, 10s)) << "safe stops seen: " << stops.size();
  for (const char* resource : {"robot", "gripper"}) {
    ASSERT_TRUE(stops.count(resource)) << resource;
    EXPECT_TRUE(stops[resource].active);
    EXPECT_EQ(stops[resource].source, "tc");
    EXPECT_NE(stops[resource].reason.find("node root/1/0"), std::string::npos) << stops[resource].reason;
    EXPECT_NE(stops[resource].reason.find("did not acknowledge SHUTDOWN"), std::string::npos)
        << stops[resource].reason;
  }
  EXPECT_FALSE(stops.count("crane")) << "the leaf did not hold the crane";
  EXPECT_FALSE(stops.count("admittance")) << "the leaf did not hold the admittance controller";
  bool journalled = false;
  for (const auto& l : journal("hung-robot"))
    journalled = journalled || (l.kind == "ESCALATION" &&
                                l.message.find("safe stop commanded for [robot,gripper]") != std::string::npos);
  EXPECT_TRUE(journalled);
}

// Every PROGRESS event is journaled, up to journal_progress_per_run per run; one row at the run's end
// counts the others, so the history is complete without a chatty skill filling the journal.
TEST_F(LifecycleTest, ProgressEventsAreJournaledUpToTheBoundPerRun) {
  start_controller({{"journal_progress_per_run", 5}});
  start_scripted("exec", {"Localize"},
                 {{"root/0", {{"mode", "succeed"}, {"delay_s", 0.3}, {"progress_steps", 30}}},
                  {"root/1", {{"mode", "succeed"}, {"delay_s", 0.1}, {"progress_steps", 3}}}});
  wait_ready({"tc", "exec"});
  submit("chatty",
         recipe("chatty", {{"type", "Sequence"}, {"children", {skill("first", "load"), skill("second", "target")}}}));
  ASSERT_TRUE(wait_finished("chatty"));
  EXPECT_EQ(last("chatty").state, rigger_task_TASK_SUCCEEDED) << last("chatty").message;
  std::size_t sent = 0;
  for (const auto& e : events_seen_)
    if (e.task == "chatty" && e.node == "root/0" && e.kind == rigger_skill_SKILL_EVENT_PROGRESS) ++sent;
  ASSERT_EQ(sent, 30U);
  std::map<std::string, std::vector<JournalLine>> progress;  // by node: PROGRESS and PROGRESS_LEFT_OUT rows
  std::vector<std::string> order;                            // root/0's EVENT rows, in order
  for (const auto& l : journal("chatty")) {
    if (l.kind != "EVENT") continue;
    if (l.code == "PROGRESS" || l.code == "PROGRESS_LEFT_OUT") progress[l.node].push_back(l);
    if (l.node == "root/0") order.push_back(l.code);
  }
  ASSERT_EQ(progress["root/0"].size(), 6U);
  for (std::size_t i = 0; i < 5; ++i) {
    EXPECT_EQ(progress["root/0"][i].code, "PROGRESS");
    EXPECT_NE(progress["root/0"][i].message.find("scripted progress"), std::string::npos)
        << progress["root/0"][i].message;
  }
  EXPECT_EQ(progress["root/0"][0].message.rfind("0.032", 0), 0U)
      << "the fraction, 1/31: " << progress["root/0"][0].message;
  EXPECT_EQ(progress["root/0"][5].code, "PROGRESS_LEFT_OUT");
  EXPECT_EQ(progress["root/0"][5].message,
            "25 more PROGRESS events of this run not journaled (journal_progress_per_run 5)");
  EXPECT_EQ(order, (std::vector<std::string>{"PROGRESS", "PROGRESS", "PROGRESS", "PROGRESS", "PROGRESS",
                                             "PROGRESS_LEFT_OUT", "SUCCESS"}));
  // Under the bound: every one, and no count.
  ASSERT_EQ(progress["root/1"].size(), 3U);
  for (const auto& l : progress["root/1"]) EXPECT_EQ(l.code, "PROGRESS");
}

// A (re)started controller learns from the executors' announcements which runs are still running or
// stopping and starts nothing on their resources until they are free. The controller is
// SIGKILLed while a skill runs whose stop takes `stop_delay_s`: the executor shuts that run down
// (CONTROLLER_LOST) and stops it while a second controller, on the same journal, takes a new task.
class RestartTest : public LifecycleTest {
 protected:
  /// Runs task "old" (Localize, camera) until the executor answered its START, kills the controller
  /// "tc" by its pid and starts "tc-2" with `extra`; returns once tc-2 reads recipes. Node root/0
  /// (the new tasks' leaf) succeeds after 0.1 s.
  void restart_while_the_old_run_stops(double stop_delay_s, const json& extra) {
    expect_clean_exit_ = false;  // tc is killed
    start_controller();
    start_scripted("exec", {"Localize"},
                   {{"root", {{"mode", "run"}, {"stop_delay_s", stop_delay_s}}},
                    {"root/0", {{"mode", "succeed"}, {"delay_s", 0.1}}}});
    wait_ready({"tc", "exec"});
    submit("old", recipe("old", skill("find", "load")));
    ASSERT_TRUE(cell_.wait_until([&] { return event_at("old", "root", rigger_skill_SKILL_EVENT_ACCEPTED); }, 20s));
    // Wake the loop when the killed controller's recipe reader is gone: a recipe written before tc-2's
    // reader matched would be lost (commands QoS is volatile).
    cell_.loop().on_status(recipes_->handle(), DDS_PUBLICATION_MATCHED_STATUS, [] {});
    ASSERT_TRUE(cell_.stop("tc", SIGKILL, 5s).has_value());
    ASSERT_TRUE(cell_.wait_until([&] { return recipes_->matched_readers() == 0; }, 10s));
    start_controller(extra, "tc-2");
    wait_ready({"tc-2"});
    ASSERT_EQ(event_at("old", "root", rigger_skill_SKILL_EVENT_STOPPED), nullptr)
        << "the old run stopped before the new task could be submitted: stop_delay_s too short for this machine";
  }
  static json one_leaf(const std::string& task_id) {
    return recipe(task_id, {{"type", "Sequence"}, {"children", {skill("find again", "target")}}});
  }
};

TEST_F(RestartTest, ARestartedControllerStartsALeafOnlyOnceTheKilledControllersRunHasStopped) {
  restart_while_the_old_run_stops(6.0, json::object());
  submit("new", one_leaf("new"));
  ASSERT_TRUE(wait_finished("new", 30s));
  EXPECT_EQ(last("new").state, rigger_task_TASK_SUCCEEDED) << last("new").code << " " << last("new").message;
  // The START went out after the executor wrote the old run's STOPPED (one host: the writers' clocks
  // are one), so the executor never had to wait for, or refuse, it.
  const EventSeen* stopped = event_at("old", "root", rigger_skill_SKILL_EVENT_STOPPED);
  const CommandSeen* start = command_at("new", "root/0", rigger_skill_SKILL_START);
  ASSERT_NE(stopped, nullptr);
  ASSERT_NE(start, nullptr);
  EXPECT_EQ(start->executor, "exec");
  EXPECT_GE(start->written, stopped->written)
      << "START sent " << (stopped->written - start->written) / 1000000 << " ms before the old run's STOPPED";
  EXPECT_EQ(count_commands("new", rigger_skill_SKILL_START), 1U);
  EXPECT_EQ(event_at("new", "root/0", rigger_skill_SKILL_EVENT_FAILURE), nullptr) << "refused (RESOURCE_BUSY?)";
  const EventSeen* accepted = event_at("new", "root/0", rigger_skill_SKILL_EVENT_ACCEPTED);
  ASSERT_NE(accepted, nullptr);
  EXPECT_EQ(accepted->code, "") << "the executor had to wait: " << accepted->message;
  // The journal says why the START waited, naming the holder.
  bool waited = false;
  for (const auto& l : journal("new"))
    waited = waited || (l.node == "root/0" && l.kind == "COMMAND" && l.code == "START_WAITS" &&
                        l.message.find("held by Localize (task old, node root) on executor exec") != std::string::npos);
  EXPECT_TRUE(waited);
  ASSERT_TRUE(wait_finished("old"));
  EXPECT_EQ(last("old").code, "INTERRUPTED");
}

TEST_F(RestartTest, AStartHeldLongerThanBusyWaitFailsItsLeafNamingTheHolder) {
  restart_while_the_old_run_stops(5.0, {{"busy_wait_s", 0.5}});
  submit("held", one_leaf("held"));
  ASSERT_TRUE(wait_finished("held", 20s));
  EXPECT_EQ(last("held").state, rigger_task_TASK_FAILED);
  EXPECT_EQ(last("held").code, "RESOURCE_HELD");
  EXPECT_EQ(last("held").failed_node, "root/0");
  const NodeSeen* failed = node_at("held", "root/0", rigger_task_NODE_FAILURE);
  ASSERT_NE(failed, nullptr);
  EXPECT_NE(failed->message.find("resource 'camera', held by Localize (task old, node root) on executor exec"),
            std::string::npos)
      << failed->message;
  EXPECT_NE(failed->message.find("for 0.5 s"), std::string::npos) << failed->message;
  EXPECT_EQ(count_commands("held", rigger_skill_SKILL_START), 0U) << "a held START is never sent";
  // Once the old run has stopped, the camera is free again.
  ASSERT_TRUE(cell_.wait_until([&] { return event_at("old", "root", rigger_skill_SKILL_EVENT_STOPPED); }, 20s));
  submit("after", one_leaf("after"));
  ASSERT_TRUE(wait_finished("after", 20s));
  EXPECT_EQ(last("after").state, rigger_task_TASK_SUCCEEDED) << last("after").code << " " << last("after").message;
}

TEST_F(RestartTest, ACancelWhileTheStartIsHeldStopsTheLeafWithoutSendingIt) {
  restart_while_the_old_run_stops(5.0, json::object());
  submit("cancel", one_leaf("cancel"));
  ASSERT_TRUE(cell_.wait_until([&] { return has_line(journal("cancel"), "root/0", "COMMAND", "START_WAITS"); }, 10s));
  command("cancel", rigger_task_TASK_CANCEL, "changed my mind");
  ASSERT_TRUE(wait_finished("cancel"));
  EXPECT_EQ(last("cancel").state, rigger_task_TASK_CANCELED);
  const NodeSeen* stopped = node_at("cancel", "root/0", rigger_task_NODE_STOPPED);
  ASSERT_NE(stopped, nullptr);
  EXPECT_TRUE(stopped->code.empty()) << "a clean stop: " << stopped->code;
  EXPECT_NE(stopped->message.find("was never started: it waited for resource 'camera', held by Localize (task old"),
            std::string::npos)
      << stopped->message;
  bool journaled = false;
  for (const auto& l : journal("cancel"))
    journaled = journaled || (l.node == "root/0" && l.kind == "EVENT" && l.code == "STOPPED" &&
                              l.message.rfind("NOT_STARTED: ", 0) == 0);
  EXPECT_TRUE(journaled);
  EXPECT_EQ(event_at("old", "root", rigger_skill_SKILL_EVENT_STOPPED), nullptr)
      << "canceled at once, not after the old run's stop";
  EXPECT_EQ(count_commands("cancel", rigger_skill_SKILL_START), 0U);
  EXPECT_EQ(count_commands("cancel", rigger_skill_SKILL_SHUTDOWN), 0U) << "nothing was sent, so nothing to stop";
}

}  // namespace
}  // namespace rigger::testing::controller
