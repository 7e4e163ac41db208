#include "rehearsal_link.hpp"

#include <unistd.h>

#include "rigger/protocol/task.hpp"

namespace rigger::console {

namespace {
constexpr std::size_t kEventCapacity = 50000;  // a rehearsal is one task at a time
// How often a started cell is looked at: a controller's arrival, the end of its command, the idle time.
constexpr std::chrono::milliseconds kCellStep{250};
// From a revision's APPLY to the rehearsal world model's report of it: it validates the document (its
// CAD models among it), seconds rather than a query's fraction of one.
constexpr std::chrono::milliseconds kRevisionTimeout{30000};
}  // namespace

RehearsalLink::RehearsalLink(std::uint32_t domain_id, dds::EventLoop& loop, const std::string& epoch,
                             std::chrono::milliseconds verdict_timeout,
                             std::optional<std::pair<LaunchCommand, LaunchTimes>> launch,
                             std::function<void(const CellChange&, const std::string&)> journal,
                             const std::string& cell_folder)
    : participant_(domain_id),
      loop_(loop),
      events_(kEventCapacity, epoch),
      state_(events_),
      tasks_(participant_, state_, skills_),
      recipes_(participant_, protocol::task::kRecipe),
      revision_(participant_, loop, "console-rehearsal-" + std::to_string(::getpid()), kRevisionTimeout),
      verdict_timeout_(verdict_timeout),
      journal_(std::move(journal)) {
  if (launch) {
    launch->first.env.push_back("RIGGER_DOMAIN=" + std::to_string(domain_id));
    launcher_ = std::make_unique<RehearsalLauncher>(std::move(launch->first), launch->second);
    cell_files_ = std::make_unique<RehearsalCellFiles>(
        cell_folder, std::filesystem::temp_directory_path() /
                         ("rigger-rehearsal-cells-" + std::to_string(::getpid()) + "-" + std::to_string(domain_id)));
  }
  dds_listener_t* listener = dds_create_listener(this);
  dds_lset_data_available(listener, [](dds_entity_t, void* self) { static_cast<RehearsalLink*>(self)->wake(); });
  for (const dds_entity_t reader : tasks_.readers()) dds_set_listener(reader, listener);
  for (const dds_entity_t reader : revision_.readers()) dds_set_listener(reader, listener);
  dds_delete_listener(listener);
  wake();  // samples that arrived before the listeners were set
}

RehearsalLink::~RehearsalLink() {
  // dds_set_listener waits for a callback in progress: none runs once this returns. Work already posted
  // to the loop never runs: the console is destroyed after its loop ended.
  for (const dds_entity_t reader : tasks_.readers()) dds_set_listener(reader, nullptr);
  for (const dds_entity_t reader : revision_.readers()) dds_set_listener(reader, nullptr);
  events_.close();
  if (launcher_ && launcher_->phase() != CellPhase::kIdle) {
    const std::string pid = std::to_string(launcher_->status().value("pid", 0));
    launcher_.reset();  // waits for the cell to stop, at most its stop timeout
    if (journal_) journal_({CellPhase::kIdle, "stopped (pid " + pid + ", the console stops)", false}, "console");
  }
}

void RehearsalLink::wake() {
  if (!wake_pending_.exchange(true)) loop_.post([this] { take(); });
}

void RehearsalLink::take() {
  wake_pending_ = false;  // before taking: samples arriving meanwhile wake the loop again
  tasks_.take_task_status();
  tasks_.take_node_status();
  tasks_.take_executors();
  revision_.take();
  settle_verdicts();
}

void RehearsalLink::publish(const std::string& task_id, const std::string& recipe_json, const std::string& submitter,
                            const CellTarget& cell, std::shared_ptr<std::promise<ActionResult>> answer) {
  const std::string domain = std::to_string(participant_.domain_id());
  // A started cell is waited for until it is ready (its world model too), even when its controller is
  // there already.
  if (launcher_ && (recipes_.matched_readers() == 0 || launcher_->phase() == CellPhase::kStarting ||
                    launcher_->restarting())) {
    std::optional<CellChange> change;
    if (!launcher_->restarting()) {
      std::string why_not;
      const std::vector<std::string> env =
          launcher_->phase() == CellPhase::kIdle ? cell_env(cell, why_not) : std::vector<std::string>{};
      change = launcher_->start(RehearsalLauncher::Clock::now(), env);
      if (change && !change->failed)
        change->what += env.empty() ? " on its own cell file" + (why_not.empty() ? "" : " (" + why_not + ")")
                                    : " on the cell's revision " + std::to_string(cell.revision);
      if (change && journal_) journal_(*change, submitter);
      if (change && change->failed) {
        answer->set_value({false, "the rehearsal cell of domain " + domain + " was not started: " + change->what, {}});
        return;
      }
      if (change && !env.empty()) restarted_for_ = cell.sha256;  // on it already: no restart helps
    }
    watch_cell();
    answer->set_value({false, "starting the rehearsal cell of domain " + domain,
                       {{"starting", true}, {"started", change.has_value()}, {"cell", cell_status()}}});
    return;
  }
  if (recipes_.matched_readers() == 0) {
    answer->set_value({false,
                       "no task controller reads recipes on the rehearsal domain " + domain +
                           " (is the rehearsal cell running? RIGGER_DOMAIN=" + domain +
                           " deploy/rigger-compose up); nothing was sent",
                       {}});
    return;
  }
  if (verdicts_.count(task_id) > 0 || bringing_.count(task_id) > 0) {
    answer->set_value({false, "a rehearsal of " + task_id + " is being sent already", {}});
    return;
  }
  if (cell.sha256.empty()) return send(task_id, recipe_json, submitter, std::move(answer));
  bringing_.insert(task_id);
  revision_.bring_to(cell, submitter, [this, task_id, recipe_json, submitter, answer, cell](const std::string& error) {
    bringing_.erase(task_id);
    if (error.empty()) {
      restarted_for_.clear();
      return send(task_id, recipe_json, submitter, answer);
    }
    std::string why_not;
    if (revision_.simulator_refused() && restart_on(cell, error, submitter, answer, why_not)) return;
    answer->set_value({false, error + (why_not.empty() ? "" : "; " + why_not) + "; nothing was sent",
                       {{"cell_refused", true}}});
  });
}

std::vector<std::string> RehearsalLink::cell_env(const CellTarget& cell, std::string& why_not) {
  if (cell.sha256.empty()) return {};  // no revision known: the cell's own file is all there is
  try {
    return {"RIGGER_CELL_FILE=" + cell_files_->write(cell).string()};
  } catch (const std::exception& e) {
    why_not = e.what();
    return {};
  }
}

bool RehearsalLink::restart_on(const CellTarget& cell, const std::string& refusal, const std::string& submitter,
                               const std::shared_ptr<std::promise<ActionResult>>& answer, std::string& why_not) {
  if (!launcher_) {
    why_not = "the rehearsal cell was started by hand: restart it on the cell's revision (its world model and "
              "cell_sim with --cell on the revision's document)";
    return false;
  }
  if (restarted_for_ == cell.sha256) {
    why_not = "it was started again on that revision already";
    return false;
  }
  std::string cannot;
  const std::vector<std::string> env = cell_env(cell, cannot);
  if (env.empty()) {
    why_not = "the rehearsal cell cannot be started on it: " + cannot;
    return false;
  }
  restarted_for_ = cell.sha256;
  revision_.forget();
  const auto change = launcher_->restart(RehearsalLauncher::Clock::now(), env,
                                         "to start on the cell's revision " + std::to_string(cell.revision) +
                                             ", which its simulator cannot take live");
  if (change && journal_) journal_(*change, submitter);
  watch_cell();
  const std::string domain = std::to_string(participant_.domain_id());
  answer->set_value({false, "restarting the rehearsal cell of domain " + domain + " on the cell's revision " +
                                std::to_string(cell.revision) + ": " + refusal,
                     {{"starting", true}, {"restarting", true}, {"started", true}, {"cell", cell_status()}}});
  return true;
}

void RehearsalLink::watch_cell() {
  if (cell_timer_ == 0) cell_timer_ = loop_.every(kCellStep, [this] { step_cell(); });
}

void RehearsalLink::send(const std::string& task_id, const std::string& recipe_json, const std::string& submitter,
                         std::shared_ptr<std::promise<ActionResult>> answer) {
  const std::string domain = std::to_string(participant_.domain_id());
  const dds_return_t rc = write_recipe(recipes_, task_id, recipe_json, submitter);
  if (rc != DDS_RETCODE_OK) {
    answer->set_value({false, std::string("publishing failed: ") + dds_strretcode(rc), {}});
    return;
  }
  // The controller's first status of the task is its verdict: accepted (then running) or rejected.
  const auto timer = loop_.after(verdict_timeout_, [this, task_id, domain] {
    auto it = verdicts_.find(task_id);
    if (it == verdicts_.end()) return;
    it->second.answer->set_value({false,
                                  "the recipe was sent, but no task controller on the rehearsal domain " + domain +
                                      " gave it a status within " +
                                      std::to_string(verdict_timeout_.count() / 1000.0).substr(0, 4) + " s",
                                  {}});
    verdicts_.erase(it);
  });
  verdicts_[task_id] = {std::move(answer), timer};
  settle_verdicts();
}

nlohmann::json RehearsalLink::cell_status() const {
  if (!launcher_) return {{"phase", "none"}, {"domain", participant_.domain_id()}};
  nlohmann::json status = launcher_->status();
  status["domain"] = participant_.domain_id();
  return status;
}

void RehearsalLink::step_cell() {
  const bool busy = watchers_ > 0 || state_.running_tasks() > 0 || !verdicts_.empty() || !bringing_.empty();
  const bool ready = recipes_.matched_readers() > 0 && revision_.world_model();
  const auto change = launcher_->step(RehearsalLauncher::Clock::now(), ready, busy);
  if (change && journal_) journal_(*change, "console");
  if (launcher_->phase() == CellPhase::kIdle) {
    loop_.cancel(cell_timer_);
    cell_timer_ = 0;
  }
}

void RehearsalLink::settle_verdicts() {
  for (auto it = verdicts_.begin(); it != verdicts_.end();) {
    nlohmann::json status = state_.task(it->first);
    if (status.is_null()) {
      ++it;
      continue;
    }
    loop_.cancel(it->second.timer);
    const bool rejected = status.value("state", "") == "REJECTED";
    const std::string why = rejected ? "the rehearsal controller refused the recipe: " + status.value("code", "") +
                                           (status.value("message", "").empty() ? "" : " " + status.value("message", ""))
                                     : "";
    it->second.answer->set_value({!rejected, why, std::move(status)});
    it = verdicts_.erase(it);
  }
}

}  // namespace rigger::console
