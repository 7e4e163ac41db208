// The controller's resume after a crash (docs/behavior-tree.md, "Resume after a crash"): an
// INTERRUPTED task's journal becomes a restored tree (resume_plan.hpp, pure), the operator is asked, and
// only the confirmation starts anything; a restarted controller first reports the tasks it finds
// unfinished as INTERRUPTED. Members of TaskControllerNode, kept apart from its wiring.
#include <algorithm>

#include <nlohmann/json.hpp>

#include "task_controller_node.hpp"

namespace rigger::task_controller {

void TaskControllerNode::report_interrupted() {
  for (const auto& t : journal_.unfinished_tasks()) {
    const std::string message =
        "the task controller stopped while the task ran; nothing runs until `riggerctl resume " + t.task_id +
        "` and the operator's confirmation";
    journal_.finish_task(t.task_id, "INTERRUPTED", codes::kInterrupted, message, wall_now_s());
    if (!status_.task(t.task_id, rigger_task_TASK_FAILED, codes::kInterrupted, message, ""))
      ctx_.log->error("task status write failed task={}", t.task_id);
    ctx_.log->warn("task interrupted task={}", t.task_id);
  }
}

bool TaskControllerNode::cancel_resuming(const std::string& task_id, const std::string& reason) {
  const auto r = resuming_.find(task_id);
  if (r == resuming_.end()) return false;
  // Canceled while the resume waited for the operator: nothing had started, the question goes.
  if (r->second.asked) prompts_.write(r->second.prompt, r->second.question, false, "resume", r->second.details_json);
  journal({wall_now_s(), task_id, "", "COMMAND", "CANCEL", reason});
  flush_side_effects();
  journal_.finish_task(task_id, "CANCELED", bt::codes::kCanceled, reason + " (before the resume was confirmed)",
                       wall_now_s());
  status_.task(task_id, rigger_task_TASK_CANCELED, bt::codes::kCanceled, reason, "");
  resuming_.erase(r);
  return true;
}

void TaskControllerNode::refuse_resume(const std::string& task_id, const std::string& why) {
  ctx_.log->warn("resume refused task={}: {}", task_id, why);
  journal({wall_now_s(), task_id, "", "RESUME", codes::kResumeRefused, why});
  flush_side_effects();
  if (!status_.task(task_id, rigger_task_TASK_FAILED, codes::kResumeRefused, why, ""))
    ctx_.log->error("task status write failed task={}", task_id);
}

void TaskControllerNode::resume_interrupted(const std::string& task_id, const std::string& issuer,
                                            const std::string& reason, bool may_wait) {
  if (pending_.count(task_id)) return;  // waiting for executors: it goes on when they are heard
  if (auto r = resuming_.find(task_id); r != resuming_.end()) {
    if (!r->second.asked) return;  // the world is being re-checked: the prompt comes once it answered
    // Asked again (another riggerctl, or the first one gave up waiting): the same question stands.
    prompts_.write(r->second.prompt, r->second.question, true, "resume", r->second.details_json);
    status_.task(task_id, rigger_task_TASK_PAUSED, codes::kResumeConfirmation, r->second.summary, "");
    return;
  }
  flush_side_effects();
  const JournalTask known = journal_.task(task_id);
  if (known.task_id.empty()) {
    ctx_.log->warn("resume of an unknown task task={}", task_id);  // riggerctl tells from the journal
    return;
  }
  if (known.state != "INTERRUPTED") {
    ctx_.log->warn("resume of a task that is not interrupted nor paused task={} state={}", task_id, known.state);
    journal({wall_now_s(), task_id, "", "REJECTED_EVENT", "WRONG_PHASE",
             "RESUME by " + issuer + ": the task is " + known.state + ", neither PAUSED nor INTERRUPTED"});
    return;
  }
  AdmissionRequest request;
  request.task_id = task_id;
  request.text = known.recipe_json;
  request.may_wait = may_wait && settings_.executor_wait.count() > 0;
  for (const auto& [id, t] : tasks_)
    if (!t->done()) request.running.push_back({id, &t->resources()});
  std::vector<std::string> problems;
  const recipe::RecipeValidator validator(executors_.live_library(&problems), settings_.validator);
  Admission admission = admit(request, validator);
  if (!known.recipe_json.empty() && admission.outcome == Admission::Outcome::kWait) {
    // A controller just restarted may not have heard every executor yet: wait for their announcements
    // (retry_pending), at most executor_wait_s, before the recipe is judged.
    ctx_.log->info("resume waits for executors task={} first={}", task_id, admission.message);
    wait_for_executors(task_id, [this, task_id, issuer, reason](bool wait) {
      resume_interrupted(task_id, issuer, reason, wait);
    });
    return;
  }
  journal({wall_now_s(), task_id, "", "COMMAND", "RESUME",
           "by " + (issuer.empty() ? std::string("an unnamed issuer") : issuer) + ": " + reason +
               " (interrupted: rebuilt from the journal; nothing starts before the operator confirms)"});
  if (known.recipe_json.empty()) {
    refuse_resume(task_id, "the journal holds no recipe for the task");
    return;
  }
  if (admission.outcome != Admission::Outcome::kAdmitted) {
    refuse_resume(task_id, "the recipe is no longer valid (" + std::string(to_string(admission.code)) +
                               "): " + admission.message);
    return;
  }
  std::unique_ptr<Task> task;
  try {
    task = std::make_unique<Task>(static_cast<TaskHost&>(*this), std::move(*admission.recipe), task_id);
  } catch (const bt::SpecError& e) {
    refuse_resume(task_id, std::string("the recipe is no longer valid: ") + e.what());
    return;
  }
  auto timeline = journal_.timeline(task_id, 10'000'000);
  Resuming r;
  r.plan = plan_resume(task->engine().spec(), timeline);
  if (!r.plan.error.empty()) {
    refuse_resume(task_id, "the journal cannot be resumed: " + r.plan.error);
    return;
  }
  // Before asking: the world model's view of the objects whose completed localizations the rest of
  // the task relies on (relocalization.hpp). The prompt waits for its answers (or their timeout).
  task->set_localizing(localizing_leaves(task->engine().spec(), validator.library()));
  r.checks = objects_to_recheck(task->engine().spec(), r.plan, timeline, validator.library(), settings_.recheck);
  r.timeline = std::move(timeline);
  r.task = std::move(task);
  r.serial = ++resume_serial_;
  r.unanswered = r.checks.size();
  std::vector<std::string> objects;
  for (const auto& c : r.checks) objects.push_back(c.object);
  const std::uint64_t serial = r.serial;
  resuming_[task_id] = std::move(r);
  if (objects.empty()) {
    ask_resume(task_id);
    return;
  }
  ctx_.log->info("resume re-checks the world task={} objects={}", task_id, objects.size());
  for (std::size_t i = 0; i < objects.size(); ++i)
    world_->pose(
        objects[i], kRecheckFrame, settings_.condition_timeout,
        [this, task_id, serial, i](const world_client::Reply& reply) { rechecked(task_id, serial, i, reply); });
}

void TaskControllerNode::rechecked(const std::string& task_id, std::uint64_t serial, std::size_t index,
                                   const world_client::Reply& reply) {
  const auto it = resuming_.find(task_id);
  if (it == resuming_.end() || it->second.serial != serial || it->second.asked) return;  // withdrawn meanwhile
  Resuming& r = it->second;
  r.checks[index].checked_at_s = wall_now_s();
  judge(r.checks[index], reply, settings_.recheck, r.task->engine().spec());
  if (--r.unanswered > 0) return;
  const std::set<std::string> again = leaves_to_relocalize(r.checks);
  if (!again.empty()) r.plan = plan_resume(r.task->engine().spec(), r.timeline, again);
  ask_resume(task_id);
}

void TaskControllerNode::ask_resume(const std::string& task_id) {
  Resuming& r = resuming_.at(task_id);
  const bt::TreeSpec& spec = r.task->engine().spec();
  bt::Activation crashes = 0;  // each crash asks its own question
  for (const auto& row : r.timeline)
    if (row.kind == "TASK" && row.code == "INTERRUPTED") ++crashes;
  r.prompt = PromptId{task_id, "resume", std::max<bt::Activation>(crashes, 1)};
  r.summary = describe_plan(r.plan, spec);
  if (!r.checks.empty()) r.summary += "\n" + describe_checks(r.checks);
  r.question.kind = bt::NodeKind::kOperatorDecision;
  r.question.id = "resume";
  r.question.name = "Resume task " + task_id;
  r.question.prompt = "The task controller restarted while task " + task_id + " ran. Resume it?\n" + r.summary;
  r.question.options = r.plan.ask.empty() ? std::vector<std::string>{"continue", "abort"}
                                          : std::vector<std::string>{"rerun", "skip", "abort"};
  r.summary += "\nprompt " + r.prompt.str() + ", options " + quoted_options(r.question.options);
  r.details_json = nlohmann::json{{"done", r.plan.done}, {"rerun", r.plan.rerun},     {"relocalize", r.plan.relocalize},
                                  {"ask", r.plan.ask},   {"pending", r.plan.pending}, {"world", to_json(r.checks)}}
                       .dump();
  r.asked = true;
  journal({wall_now_s(), task_id, "", "RESUME", "PLAN", r.summary});
  journal({wall_now_s(), task_id, "resume", "OPERATOR", "ASK", r.question.prompt});
  flush_side_effects();
  if (!prompts_.write(r.prompt, r.question, true, "resume", r.details_json))
    ctx_.log->error("prompt write failed task={}", task_id);
  if (!status_.task(task_id, rigger_task_TASK_PAUSED, codes::kResumeConfirmation, r.summary, ""))
    ctx_.log->error("task status write failed task={}", task_id);
  ctx_.log->info("resume waits for the operator task={} prompt={} relocalize={}", task_id, r.prompt.str(),
                 r.plan.relocalize.size());
}

void TaskControllerNode::answer_resume(const PromptId& id, const std::string& answer, const std::string& by) {
  auto it = resuming_.find(id.task_id);
  if (it == resuming_.end() || !it->second.asked || !(it->second.prompt == id)) return;
  Resuming& r = it->second;
  const std::string& task_id = id.task_id;
  if (!option_index(r.question.options, answer)) {
    journal({wall_now_s(), task_id, "resume", "REJECTED_EVENT", "NOT_AN_OPTION",
             "answer \"" + answer + "\" by " + by + ": expected one of " + quoted_options(r.question.options)});
    return;
  }
  prompts_.write(r.prompt, r.question, false, "resume", r.details_json);
  journal({wall_now_s(), task_id, "resume", "OPERATOR", "ANSWER", answer + " by " + by});
  if (answer == "abort") {
    const std::string message = "resume aborted by " + by + "; nothing was started";
    flush_side_effects();
    if (!journal_.finish_task(task_id, "FAILED", codes::kResumeAborted, message, wall_now_s()))
      ctx_.log->error("journal write failed task={}: {}", task_id, journal_.last_error());
    status_.task(task_id, rigger_task_TASK_FAILED, codes::kResumeAborted, message, "");
    ctx_.log->info("resume aborted task={} by={}", task_id, by);
    resuming_.erase(it);
    return;
  }
  std::unique_ptr<Task> task = std::move(r.task);
  if (answer == "skip") skip_interrupted(r.plan, task->engine().spec(), by);
  journal({wall_now_s(), task_id, "", "RESUME", "CONFIRMED",
           answer + " by " + by + "\n" + describe_plan(r.plan, task->engine().spec())});
  const bt::Restoration restoration = std::move(r.plan.restoration);
  resuming_.erase(it);
  flush_side_effects();
  if (!journal_.reopen_task(task_id, "resumed after the task controller restarted; confirmed by " + by, wall_now_s()))
    ctx_.log->error("journal write failed task={}: {}", task_id, journal_.last_error());
  task->mark_resumed();
  Task& t = *task;
  tasks_[task_id] = std::move(task);
  status_.task(task_id, rigger_task_TASK_RUNNING, "", "resumed; confirmed by " + by, "");
  ctx_.log->info("task resumed task={} by={} answer={}", task_id, by, answer);
  t.log_result("resume", "root", t.engine().start(restoration));
}

}  // namespace rigger::task_controller
