#pragma once
/// @file
/// The console's link to the rehearsal cell (docs/console.md, "Rehearsal"): the simulated cell run on a
/// DDS domain of its own (configuration key rehearsal_domain), where a planned recipe runs first. It owns
/// a second participant on that domain, its recipe writer and a TaskFeed that reads the rehearsal
/// controller's task and node statuses and its executors into a ConsoleState, EventLog and SkillCatalog
/// of their own: the rehearsal's trees never mix with the cell's. A rehearsal is answered with the
/// rehearsal controller's verdict (its first status of the task), so its validator has the last word.
///
/// The console stays one process with one work loop: a waitset holds only entities of its own
/// participant, so this participant's readers get a data-available listener that only wakes that loop
/// (post), where the samples are taken.
#include <atomic>
#include <chrono>
#include <cstdint>
#include <future>
#include <map>
#include <memory>
#include <string>

#include "console_state.hpp"
#include "event_log.hpp"
#include "http_api.hpp"
#include "planner.hpp"
#include "rigger/dds/event_loop.hpp"
#include "rigger/dds/participant.hpp"
#include "rigger/dds/pubsub.hpp"
#include "task_feed.hpp"

namespace rigger::console {

class RehearsalLink {
 public:
  /// Joins `domain_id`; the samples are taken on `loop`. `epoch` numbers the rehearsal's event stream
  /// (the console's start); `verdict_timeout`: how long publish() waits for the controller's first status.
  /// @throws DdsError.
  RehearsalLink(std::uint32_t domain_id, dds::EventLoop& loop, const std::string& epoch,
                std::chrono::milliseconds verdict_timeout);
  ~RehearsalLink();
  RehearsalLink(const RehearsalLink&) = delete;
  RehearsalLink& operator=(const RehearsalLink&) = delete;

  /// What the HTTP side reads (valid as long as this link).
  RehearsalFeed feed() { return {participant_.domain_id(), state_, events_}; }

  /// Publishes the recipe on the rehearsal domain and sets `answer` to the rehearsal controller's verdict:
  /// ok with its first status of the task as data (ACCEPTED, RUNNING, ...); !ok with that status as data
  /// when it REJECTED the recipe (with its errors); !ok with no data when no controller reads recipes
  /// there (nothing sent) or none answered within the verdict timeout. Loop thread only.
  void publish(const std::string& task_id, const std::string& recipe_json, const std::string& submitter,
               std::shared_ptr<std::promise<ActionResult>> answer);

 private:
  void wake();  // any thread (a listener's): the loop takes the samples
  void take();
  void settle_verdicts();  // answers the publishes whose task the controller has given a status

  dds::Participant participant_;  // first: destroyed last
  dds::EventLoop& loop_;
  EventLog events_;
  ConsoleState state_;
  SkillCatalog skills_;
  TaskFeed tasks_;
  dds::Writer<rigger_task_Recipe> recipes_;
  std::atomic<bool> wake_pending_{false};
  std::chrono::milliseconds verdict_timeout_;
  struct Verdict {
    std::shared_ptr<std::promise<ActionResult>> answer;
    dds::EventLoop::TimerId timer = 0;
  };
  std::map<std::string, Verdict> verdicts_;  ///< by task id
};

}  // namespace rigger::console
