// riggerctl cancel, pause and resume: a TaskCommand and the controller's acknowledgement; for pause and
// resume, what each leaf's executor answered.
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <map>
#include <vector>

#include "rigger/base/time.hpp"
#include "rigger/dds/conversions.hpp"
#include "rigger/protocol/skill.hpp"
#include "rigger/protocol/task_names.hpp"
#include "rigger/skill_protocol/leaf_outcome.hpp"
#include "task_support.hpp"

namespace rigger::ctl::tasks {
namespace {

using protocol::task::task_state_name;

/// Writes one TaskCommand, issued by riggerctl:$USER.
void send_task_command(dds::Writer<rigger_task_TaskCommand>& commands, const std::string& task_id,
                       rigger_task_TaskCommandKind kind, const std::string& reason) {
  rigger_task_TaskCommand c{};
  const std::string issuer = riggerctl_source();
  c.task_id = dds::wire_string(task_id);
  c.kind = kind;
  c.reason = dds::wire_string(reason);
  c.issuer = dds::wire_string(issuer);
  c.seq = 1;
  c.stamp = dds::wire_now();
  commands.write(c);
}

/// RESUME of an INTERRUPTED task (the controller restarted while it ran): the controller rebuilds it from
/// its journal and asks the operator (prompt kind "resume"). Prints what was done and what will run, and
/// the prompt to answer; exit 0 when the controller waits for the confirmation, 1 when it refused.
int resume_interrupted(dds::Writer<rigger_task_TaskCommand>& commands, dds::Reader<rigger_task_TaskStatus>& statuses,
                       dds::EventLoop& loop, const std::string& task_id, const std::string& reason, double timeout_s) {
  bool sent = false, done = false, before = false;
  std::string code, message;
  loop.on_data(statuses, [&] {
    statuses.take([&](const rigger_task_TaskStatus& s, const dds_sample_info_t&) {
      if (dds::to_string(s.task_id) != task_id) return;
      before = true;
      if (!sent) return;
      const std::string c = dds::to_string(s.code);
      if (c != "RESUME_CONFIRMATION" && c != "RESUME_REFUSED") return;  // the state from before the command
      done = true;
      code = c;
      message = dds::to_string(s.message);
    });
  });
  // The task's status from before (INTERRUPTED, or an earlier resume's answer) is not this one's answer.
  loop.run_until([&] { return before; }, std::chrono::milliseconds(1000));
  sent = true;
  send_task_command(commands, task_id, rigger_task_TASK_RESUME, reason);
  if (!loop.run_until([&] { return done; }, from_seconds(timeout_s))) {
    std::fprintf(stderr, "riggerctl: the task controller did not answer the resume of task %s within %.1f s\n",
                 task_id.c_str(), timeout_s);
    return kExitFailed;
  }
  if (code == "RESUME_REFUSED") {
    std::fprintf(stderr, "riggerctl: task %s cannot be resumed: %s\n", task_id.c_str(), message.c_str());
    return kExitFailed;
  }
  std::printf("task %s was INTERRUPTED (the task controller restarted while it ran)\n%s\n", task_id.c_str(),
              message.c_str());
  std::printf("nothing runs until the operator confirms: answer the prompt kind resume in `riggerctl operator`\n");
  return 0;
}

}  // namespace

int task_command(const CommonOptions& common, const std::string& task_id, rigger_task_TaskCommandKind kind,
                 const std::string& reason, double timeout_s) {
  dds::Participant participant(common.domain);
  dds::Writer<rigger_task_TaskCommand> commands(participant, protocol::task::kCommand);
  dds::Reader<rigger_task_TaskStatus> statuses(participant, protocol::task::kStatus);
  JournalTopics topics(participant);
  dds::EventLoop loop(participant);
  if (!commands.wait_for_readers(1, from_seconds(timeout_s))) {
    std::fprintf(stderr, "riggerctl: no task controller on %s\n", dds::describe_domain(common.domain).c_str());
    return kExitNoController;
  }
  // The journal knows whether the task exists and whether it already ended (its last line is the
  // TASK result): the controller ignores commands for such tasks, so there is nothing to wait for.
  const JournalAnswer journal = ask_journal(topics, loop, task_id, timeout_s);
  if (const int failed = journal_failure(journal, common, timeout_s, "no task " + task_id)) return failed;
  // The last TASK line is the task's state: a resumed task has INTERRUPTED, then RUNNING, then its end.
  const JournalLine* task_line = nullptr;
  for (const auto& l : journal.lines)
    if (l.kind == "TASK") task_line = &l;
  if (task_line != nullptr && task_line->code == "INTERRUPTED" && kind == rigger_task_TASK_RESUME)
    return resume_interrupted(commands, statuses, loop, task_id, reason, timeout_s);
  if (task_line != nullptr && task_line->code != "RUNNING") {
    std::printf("task %s had already ended: %s\n", task_id.c_str(), task_line->code.c_str());
    return kind == rigger_task_TASK_CANCEL && task_line->code == "CANCELED" ? 0 : kExitFailed;
  }
  const int wanted = kind == rigger_task_TASK_CANCEL  ? rigger_task_TASK_CANCELED
                     : kind == rigger_task_TASK_PAUSE ? rigger_task_TASK_PAUSED
                                                      : rigger_task_TASK_RUNNING;
  bool sent = false, done = false;
  int state = -1, before = -1;
  // PAUSE / RESUME: what each leaf did. Each executor answers PAUSED (RESUMED), with a code when the
  // leaf runs on; which leaves were asked, the journal says (below).
  const bool leaves = kind != rigger_task_TASK_CANCEL;
  const auto leaf_answer =
      kind == rigger_task_TASK_PAUSE ? skill_protocol::EventKind::kPaused : skill_protocol::EventKind::kResumed;
  dds::Reader<rigger_skill_SkillEvent> leaf_answers(participant, protocol::skill::kEvent);
  std::map<std::string, std::string> answered;  // by node id: what its executor answered
  if (leaves) {
    loop.on_data(leaf_answers, [&] {
      leaf_answers.take([&](const rigger_skill_SkillEvent& e, const dds_sample_info_t&) {
        if (!sent || dds::to_string(e.task_id) != task_id) return;
        const skill_protocol::LeafOutcome outcome = skill_protocol::from_wire(e);
        if (outcome.kind != leaf_answer) return;
        answered[dds::to_string(e.node_id)] = (outcome.code.empty() ? "" : outcome.code + ": ") + outcome.message;
      });
    });
  }
  loop.on_data(statuses, [&] {
    statuses.take([&](const rigger_task_TaskStatus& s, const dds_sample_info_t&) {
      if (dds::to_string(s.task_id) != task_id) return;
      if (!sent) before = s.state;
      if (task_terminal(s.state) || (sent && s.state == wanted)) {
        done = true;
        state = s.state;
      }
    });
  });
  // The task's current state (transient-local) first, so that a state from before the command is
  // not taken for its acknowledgement.
  loop.run_until([&] { return before >= 0; }, std::chrono::milliseconds(1000));
  if (done) {
    std::printf("task %s had already ended: %s\n", task_id.c_str(), task_state_name(state));
    return state == wanted ? 0 : kExitFailed;
  }
  if (before == wanted && kind == rigger_task_TASK_RESUME) {
    std::fprintf(stderr, "riggerctl: task %s is RUNNING, neither PAUSED nor INTERRUPTED: nothing to resume\n",
                 task_id.c_str());
    return kExitFailed;
  }
  if (before == wanted) {
    std::printf("task %s is %s already\n", task_id.c_str(), task_state_name(before));
    return 0;
  }
  sent = true;
  send_task_command(commands, task_id, kind, reason);
  if (!loop.run_until([&] { return done; }, from_seconds(timeout_s))) {
    std::fprintf(stderr, "riggerctl: task %s was not %s within %.1f s\n", task_id.c_str(), task_state_name(wanted),
                 timeout_s);
    return kExitFailed;
  }
  std::printf("task %s %s\n", task_id.c_str(), task_state_name(state));
  if (leaves && state == wanted) {
    // The controller journals a COMMAND row per leaf it sends the command to, in the same turn as the
    // acknowledgement, and each answer as an EVENT row (PAUSED, or NOT_PAUSED with the code). The leaves
    // asked this time are the rows after the last task-level one. Answers come live on
    // rigger/skill/event, or from the journal when this reader had not yet matched an executor's writer.
    const std::string command = kind == rigger_task_TASK_PAUSE ? "PAUSE" : "RESUME";
    std::vector<std::string> asked;
    std::uint64_t request = 2;
    const auto read_journal = [&] {
      std::map<std::string, std::string> journaled;  // this command's answers only
      asked.clear();
      for (const auto& l : ask_journal(topics, loop, task_id, timeout_s, request++).lines) {
        if (l.kind == "COMMAND" && l.code == command && l.node_id.empty()) {
          asked.clear();
          journaled.clear();
        } else if (l.kind == "COMMAND" && l.code == command) {
          asked.push_back(l.node_id);
        } else if (l.kind == "EVENT" && (l.code == skill_protocol::answer_name(leaf_answer, false) ||
                                         l.code == skill_protocol::answer_name(leaf_answer, true))) {
          journaled[l.node_id] = l.message;
        }
      }
      answered.insert(journaled.begin(), journaled.end());
    };
    const auto all_answered = [&] {
      return std::all_of(asked.begin(), asked.end(), [&](const std::string& n) { return answered.count(n) > 0; });
    };
    const auto deadline = std::chrono::steady_clock::now() + from_seconds(timeout_s);
    read_journal();
    while (!all_answered() && std::chrono::steady_clock::now() < deadline) {
      loop.run_until(all_answered, std::chrono::milliseconds(300));  // woken by a live answer
      if (!all_answered()) read_journal();
    }
    for (const auto& node : asked) {
      const auto a = answered.find(node);
      std::printf("  %s: %s\n", node.c_str(), a == answered.end() ? "no answer" : a->second.c_str());
    }
  }
  if (kind == rigger_task_TASK_PAUSE && state == wanted)
    std::printf("no new leaf starts until `riggerctl resume %s`; running leaves of pausable skills hold still, "
                "those that cannot pause run on (monitors, operator prompts) or, holding a device, are brought to "
                "their safe stop\n",
                task_id.c_str());
  return state == wanted ? 0 : kExitFailed;
}

}  // namespace rigger::ctl::tasks
