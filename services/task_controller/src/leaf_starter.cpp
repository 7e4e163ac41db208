// Task's leaf starter: a leaf's START sent (or held back, held_starts.cpp), sent again while unanswered,
// and failed START_UNANSWERED when its executor never answers.
#include <chrono>

#include "rigger/base/text.hpp"
#include "task_port.hpp"

namespace rigger::task_controller {

using bt::NodeState;

void Task::start_leaf(const bt::NodeSpec& spec, bt::Activation activation) {
  // A run of another task (a killed controller's, still stopping) may hold a resource of the leaf: the
  // START waits for the announcement that frees it, instead of being refused RESOURCE_BUSY.
  // An executor announced a moment ago may not have a reader on the command topic matched yet; a START
  // written then would reach nobody, so it waits for the match the same way.
  const std::string holder = waits_for(spec);
  if (holder.empty() || host_.pick_executor(spec.leaf, spec.executor).empty()) {
    send_start(spec, activation);
    return;
  }
  const double wait_s = std::chrono::duration<double>(host_.busy_wait()).count();
  host_.log()->info("start waits task={} node={} skill={} for=\"{}\"", id_, spec.id, spec.leaf, holder);
  host_.journal({wall_now_s(), id_, spec.id, "COMMAND", codes::kStartWaits,
                 spec.leaf + " waits (at most " + number_text(wait_s) + " s) for " + holder});
  held_[spec.id] = Held{activation, arm_held(spec.id, activation), holder, false};
}

void Task::send_start(const bt::NodeSpec& spec, bt::Activation activation) {
  const std::string executor_id = host_.pick_executor(spec.leaf, spec.executor);
  if (executor_id.empty()) {
    const std::string why =
        "no live executor offers " + spec.leaf + (spec.executor.empty() ? std::string() : " as " + spec.executor);
    host_.journal({wall_now_s(), id_, spec.id, "COMMAND", codes::kNoExecutor, why});
    std::string node_id = spec.id;
    defer([node_id, activation, why](Task& t) {
      t.log_result("executor lost", node_id, t.engine().on_leaf_lost(node_id, activation, why));
    });
    return;
  }
  end_progress(spec.id);  // a run whose end never came (its stop timed out) before this one
  const LeafRun run{{executor_id, host_.endpoint().next_seq(), host_.endpoint().routable(executor_id)}, activation};
  runs_[spec.id] = run;
  const std::string& params = params_text(spec);
  host_.journal({wall_now_s(), id_, spec.id, "COMMAND", "START",
                 spec.leaf + " on " + executor_id + " seq " + std::to_string(run.start_seq) + " " + params});
  if (!host_.endpoint().send(rigger_skill_SKILL_START, id_, spec.id, spec.leaf, run, params, ""))
    host_.log()->error("skill command write failed task={} node={}", id_, spec.id);
  TaskHost* host = &host_;
  const std::string task_id = id_, node_id = spec.id;
  const std::uint64_t seq = run.start_seq;
  if (auto u = unanswered_.find(node_id); u != unanswered_.end()) host_.loop().cancel(u->second);
  unanswered_[node_id] = host_.loop().after(host_.start_answer_timeout(), [host, task_id, node_id, seq] {
    if (Task* t = host->find_task(task_id)) t->start_unanswered(node_id, seq);
  });
  arm_resend(node_id, seq, 0);
}

void Task::arm_resend(const std::string& node_id, std::uint64_t start_seq, unsigned sent_again) {
  if (auto r = resends_.find(node_id); r != resends_.end()) {
    host_.loop().cancel(r->second);  // a START sent before (a fired id is ignored)
    resends_.erase(r);
  }
  if (sent_again >= kStartResends) return;
  TaskHost* host = &host_;
  const std::string task_id = id_;
  resends_[node_id] =
      host_.loop().after(host_.start_resend() * (1u << sent_again), [host, task_id, node_id, start_seq, sent_again] {
        if (Task* t = host->find_task(task_id)) t->resend_start(node_id, start_seq, sent_again);
      });
}

const bt::NodeSpec* Task::unanswered_and_running(const std::string& node_id, std::uint64_t start_seq) const {
  const auto run = runs_.find(node_id);
  if (unanswered_.count(node_id) == 0 || run == runs_.end() || run->second.start_seq != start_seq) return nullptr;
  const auto index = engine_->find(node_id);
  if (!index) return nullptr;
  const auto& st = engine_->status(*index);
  // The engine stops it, or stopped it: its SHUTDOWN went (or goes), and its stop timeout covers it.
  if (st.activation != run->second.activation || st.state != NodeState::kRunning) return nullptr;
  return &engine_->spec().nodes[*index];
}

void Task::resend_start(const std::string& node_id, std::uint64_t start_seq, unsigned sent_again) {
  const bt::NodeSpec* leaf = unanswered_and_running(node_id, start_seq);
  if (leaf == nullptr) return;
  const bt::NodeSpec& spec = *leaf;
  const LeafRun& run = runs_.at(node_id);
  // The same seq on the same writer: an executor that did take the first one drops this one.
  host_.log()->warn("start sent again task={} node={} executor={} seq={}: no answer yet", id_, node_id,
                    run.executor_id, start_seq);
  const double waited_s = std::chrono::duration<double>(host_.start_resend() * ((2u << sent_again) - 1)).count();
  host_.journal({wall_now_s(), id_, node_id, "COMMAND", codes::kStartSentAgain,
                 spec.leaf + " on " + run.executor_id + " seq " + std::to_string(start_seq) + ": no answer after " +
                     number_text(waited_s) + " s"});
  if (!host_.endpoint().send(rigger_skill_SKILL_START, id_, spec.id, spec.leaf, run, params_text(spec), ""))
    host_.log()->error("skill command write failed task={} node={}", id_, node_id);
  arm_resend(node_id, start_seq, sent_again + 1);
}

void Task::start_unanswered(const std::string& node_id, std::uint64_t start_seq) {
  const bt::NodeSpec* leaf = unanswered_and_running(node_id, start_seq);
  const auto run = runs_.find(node_id);
  if (run != runs_.end() && run->second.start_seq == start_seq) unanswered_.erase(node_id);  // its timer fired
  if (leaf == nullptr) return;
  const bt::NodeSpec& spec = *leaf;
  const double waited_s = std::chrono::duration<double>(host_.start_answer_timeout()).count();
  const std::string why = "START of " + spec.leaf + " (seq " + std::to_string(start_seq) + ") got no answer from " +
                          run->second.executor_id + " within " + number_text(waited_s) + " s";
  host_.log()->error("start unanswered task={} node={} executor={} seq={}", id_, node_id, run->second.executor_id,
                     start_seq);
  // Should the START arrive late after all, the executor stops that run again at once.
  send_shutdown(spec, run->second, codes::kStartUnanswered);
  end_progress(node_id);
  own_event(node_id, bt::LeafEventKind::kFailure, run->second.activation, codes::kStartUnanswered, why,
            "start unanswered");
}

}  // namespace rigger::task_controller
