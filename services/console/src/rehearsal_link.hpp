#pragma once
/// @file
/// The console's link to the rehearsal cell (docs/console.md, "Rehearsal"): the simulated cell run on a
/// DDS domain of its own (configuration key rehearsal_domain), where a planned recipe runs first. It owns
/// a second participant on that domain, its recipe writer and a TaskFeed that reads the rehearsal
/// controller's task and node statuses and its executors into a ConsoleState, EventLog and SkillCatalog
/// of their own: the rehearsal's trees never mix with the cell's. A rehearsal is answered with the
/// rehearsal controller's verdict (its first status of the task), so its validator has the last word.
///
/// With a start command (configuration `rehearsal/start`), a rehearsal that finds no controller there
/// starts the rehearsal cell (RehearsalLauncher) instead of failing; it is ready once a controller reads
/// recipes and a world model answers cell requests there, and it is stopped again after
/// `rehearsal/idle_stop_s` without a rehearsal running or a page watching one. Each rehearsal runs on the
/// real cell's running revision (RehearsalRevision). The started cell starts on that revision's document
/// (RehearsalCellFiles, RIGGER_CELL_FILE), and is started again on it when its simulator cannot take a
/// revision live (one that reshapes the crane's load): once per revision.
///
/// The console stays one process with one work loop: a waitset holds only entities of its own
/// participant, so this participant's readers get a data-available listener that only wakes that loop
/// (post), where the samples are taken.
#include <atomic>
#include <chrono>
#include <cstdint>
#include <functional>
#include <future>
#include <map>
#include <memory>
#include <optional>
#include <set>
#include <string>

#include "console_state.hpp"
#include "event_log.hpp"
#include "http_api.hpp"
#include "planner.hpp"
#include "rehearsal_cell_file.hpp"
#include "rehearsal_launcher.hpp"
#include "rehearsal_revision.hpp"
#include "rigger/dds/event_loop.hpp"
#include "rigger/dds/participant.hpp"
#include "rigger/dds/pubsub.hpp"
#include "task_feed.hpp"

namespace rigger::console {

class RehearsalLink {
 public:
  /// Joins `domain_id`; the samples are taken on `loop`. `epoch` numbers the rehearsal's event stream
  /// (the console's start); `verdict_timeout`: how long publish() waits for the controller's first status.
  /// `launch`: how to start the rehearsal cell on demand (none: it is started by hand); `journal` is
  /// told of each change of the started cell and who caused it (the submitter for a start, "console"
  /// otherwise). `cell_folder`: the rehearsal cell's own cell folder, where the models a revision does
  /// not pin are (RehearsalCellFiles; empty: unknown). @throws DdsError.
  RehearsalLink(std::uint32_t domain_id, dds::EventLoop& loop, const std::string& epoch,
                std::chrono::milliseconds verdict_timeout,
                std::optional<std::pair<LaunchCommand, LaunchTimes>> launch = std::nullopt,
                std::function<void(const CellChange&, const std::string& who)> journal = {},
                const std::string& cell_folder = {});
  ~RehearsalLink();
  RehearsalLink(const RehearsalLink&) = delete;
  RehearsalLink& operator=(const RehearsalLink&) = delete;

  /// What the HTTP side reads (valid as long as this link).
  RehearsalFeed feed() { return {participant_.domain_id(), state_, events_, watchers_}; }

  /// Brings the rehearsal world model to `cell`, the real cell's running revision (RehearsalRevision;
  /// nothing to do when its sha256 is unknown), then publishes the recipe on the rehearsal domain and
  /// sets `answer` to the rehearsal controller's verdict:
  /// ok with its first status of the task as data (ACCEPTED, RUNNING, ...); !ok with that status as data
  /// when it REJECTED the recipe (with its errors); !ok with no data when no controller reads recipes
  /// there (nothing sent) or none answered within the verdict timeout. With a launcher and no controller:
  /// nothing is sent, the rehearsal cell is started, and the answer is !ok with data {"starting": true,
  /// "started": whether this call started it, "cell": its status()} (a start that fails at once: !ok with
  /// the reason); the cell starts on `cell`'s document when it can be written (else on its own cell
  /// file, `cell` applied after). When the simulator refuses `cell` and the launcher has not restarted
  /// the cell for it yet: the cell is restarted on its document, the answer as for a start with
  /// "restarting": true. When the rehearsal world model is not brought to `cell` (it refused the
  /// document, it is not there, it did not report the revision in time, the simulator refused it and the
  /// cell cannot be restarted on it): !ok with data {"cell_refused": true}, nothing sent. Loop thread only.
  void publish(const std::string& task_id, const std::string& recipe_json, const std::string& submitter,
               const CellTarget& cell, std::shared_ptr<std::promise<ActionResult>> answer);

  /// The started rehearsal cell: RehearsalLauncher::status() with "domain", or {"phase": "none"} without a
  /// start command. Loop thread only.
  nlohmann::json cell_status() const;

 private:
  void wake();  // any thread (a listener's): the loop takes the samples
  void take();
  void settle_verdicts();  // answers the publishes whose task the controller has given a status
  void send(const std::string& task_id, const std::string& recipe_json, const std::string& submitter,
            std::shared_ptr<std::promise<ActionResult>> answer);  // the recipe, once the cell runs the revision
  void step_cell();        // the launcher's state machine, every kCellStep while the cell is not idle
  void watch_cell();       // steps the launcher until it is idle again
  /// RIGGER_CELL_FILE for a start on `cell`; empty, with `why_not`, when its document cannot be written.
  std::vector<std::string> cell_env(const CellTarget& cell, std::string& why_not);
  /// The simulator refused `cell`: restarts the cell on it, or says why not (then `answer` is untouched).
  bool restart_on(const CellTarget& cell, const std::string& refusal, const std::string& submitter,
                  const std::shared_ptr<std::promise<ActionResult>>& answer, std::string& why_not);

  dds::Participant participant_;  // first: destroyed last
  dds::EventLoop& loop_;
  EventLog events_;
  ConsoleState state_;
  SkillCatalog skills_;
  TaskFeed tasks_;
  dds::Writer<rigger_task_Recipe> recipes_;
  RehearsalRevision revision_;
  std::set<std::string> bringing_;  ///< task ids held while the rehearsal cell is brought to the revision
  std::atomic<bool> wake_pending_{false};
  std::chrono::milliseconds verdict_timeout_;
  struct Verdict {
    std::shared_ptr<std::promise<ActionResult>> answer;
    dds::EventLoop::TimerId timer = 0;
  };
  std::map<std::string, Verdict> verdicts_;  ///< by task id
  std::atomic<int> watchers_{0};             ///< open /api/rehearsal/events streams
  std::unique_ptr<RehearsalLauncher> launcher_;  ///< null: the rehearsal cell is started by hand
  std::unique_ptr<RehearsalCellFiles> cell_files_;  ///< with a launcher: the documents it starts on
  std::string restarted_for_;  ///< the sha256 of the revision the cell was last restarted on
  std::function<void(const CellChange&, const std::string&)> journal_;
  dds::EventLoop::TimerId cell_timer_ = 0;   ///< 0: the cell is idle
};

}  // namespace rigger::console
