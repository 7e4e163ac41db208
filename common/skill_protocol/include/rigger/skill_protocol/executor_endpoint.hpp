#pragma once
/// @file
/// The executor side of the skill protocol. An executor announces what it offers on
/// rigger/skill/executors (liveliness-monitored, so the controller sees it die or hang), receives the
/// SkillCommands addressed to it on rigger/skill/command, and reports SkillEvents on rigger/skill/event.
///
/// Protocol rules enforced here, so that no skill has to:
///  - commands for other executors are ignored; a command whose seq was seen before from the same
///    controller writer is a duplicate and is dropped (logged), and so is one older than the last
///    CommandOrder::kWindow seen (stale); an older seq not seen yet is a command the controller sent
///    again because the first one never arrived (a START written while discovery was still under way),
///    and is taken;
///  - START with unparsable params → FAILURE `BAD_PARAMS`; for a skill not in the library →
///    FAILURE `UNKNOWN_SKILL`;
///  - every START is answered, never dropped: ACCEPTED when it runs (just before the skill's start
///    handler), ACCEPTED `WAITING` when it first waits, or FAILURE with a code; a START whose node or resources (the
///    skill description's `resources`, "$param" resolved) are held by a run that is being stopped waits until that run
///    has stopped, then starts (or, after Options::start_wait, fails `STILL_STOPPING`); one whose node runs here and
///    was not asked to stop fails `ALREADY_RUNNING`; one whose resources a running (not stopping) skill holds fails
///    `RESOURCE_BUSY`, naming the holder;
///  - the controller's liveliness is watched through its command writer's lease (the controller
///    offers MANUAL_BY_PARTICIPANT liveliness on rigger/skill/command): when the writer that started
///    a run is lost (killed, hung, or gone), that run is shut down (reason `CONTROLLER_LOST`) so no
///    motion is left without a supervisor;
///  - SHUTDOWN for a node that does not run here → STOPPED `NOT_RUNNING` at once (it ended, or never
///    started), so the controller never waits for a stop timeout because of a race;
///  - every PAUSE / RESUME is answered at once with PAUSED / RESUMED: code empty when the skill now holds
///    (continues); `NOT_PAUSABLE` when its description is not `pausable` (or the executor pauses
///    nothing), and it keeps running — except a skill (not a monitor) that holds a device (robot,
///    crane, gripper, admittance): it cannot hold its devices still, so it is brought to its safe stop
///    (answer `NOT_PAUSABLE_STOPPED`) and its run ends FAILURE `NOT_PAUSABLE` ("could not pause"), or,
///    still waiting here to start, it never starts (the same FAILURE); `STOPPING` for a run being
///    stopped (its safe stop proceeds);
///    `ALREADY_PAUSED` / `NOT_PAUSED` for a repeated command; `NOT_RUNNING` for a node not active here
///    (command_seq 0). A START still waiting here takes the pause with it: it starts paused. Runs of
///    skills only pause; monitors keep monitoring;
///  - every event carries a per-executor seq and the seq of the START it belongs to (`start_seq`);
///    after SUCCESS, FAILURE or STOPPED the run is over and further reports for it are dropped;
///  - the announcement lists the runs active here (task, node, skill, resources, stopping) and is
///    written again at once when that set changes (a run starts, is asked to stop, or ends), after the
///    event that changed it: a controller that reads an announcement without a run has seen its end.
/// All callbacks run on the service's event loop thread.

#include <chrono>
#include <cstdint>
#include <deque>
#include <functional>
#include <map>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

#include "rigger/base/logging.hpp"
#include "rigger/dds/event_loop.hpp"
#include "rigger/dds/pubsub.hpp"
#include "rigger/skill/skill_description.hpp"
#include "rigger/skill_protocol/announced_run.hpp"
#include "rigger/skill_protocol/leaf_outcome.hpp"

namespace rigger::skill_protocol {

/// Which commands of one controller writer were taken. The controller numbers its commands in the order
/// written and sends a START again (same seq, same writer) when it got no answer: a command can arrive
/// once more, or late behind newer ones, but never twice here. Pure logic.
class CommandOrder {
 public:
  /// How many of the newest seqs are remembered; an older seq is dropped as stale.
  static constexpr std::size_t kWindow = 1024;
  /// Whether `seq` is taken: not seen before and not older than the window. `last` receives the
  /// newest seq seen before this call.
  bool accept(std::uint64_t seq, std::uint64_t* last = nullptr);

 private:
  std::set<std::uint64_t> seen_;  ///< the newest kWindow seqs taken
};

/// One run of a leaf. The START's seq tells a re-run of the same node (Retry, Repeat) from the last one.
struct LeafRun {
  std::string task_id;
  std::string node_id;
  std::uint64_t start_seq = 0;
};

struct StartRequest {
  LeafRun run;
  std::string skill;
  nlohmann::json params;  ///< an object; the controller has validated and filled defaults
};

struct ShutdownRequest {
  LeafRun run;
  std::string reason;
};

/// A PAUSE (`pause`) or RESUME of a run of a pausable skill active here.
struct PauseRequest {
  LeafRun run;
  bool pause = true;
  std::string reason;
};
/// The handler's answer: `code` empty when the skill now holds (continues), else why not.
struct PauseAnswer {
  std::string code;
  std::string message;
};

class ExecutorEndpoint {
 public:
  struct Handlers {
    std::function<void(const StartRequest&)> on_start;
    std::function<void(const ShutdownRequest&)> on_shutdown;
    /// PAUSE / RESUME of a run whose skill is pausable; empty: this executor pauses nothing.
    std::function<PauseAnswer(const PauseRequest&)> on_pause = {};
  };
  struct Options {
    /// How long a START waits for the run that holds its node or resources to finish stopping.
    std::chrono::milliseconds start_wait{10000};
    /// Called with each command taken, before it is handled, and the wall-clock instant (ns since the
    /// epoch) its handler began: a receipt trace for benchmarks (scripted_executor's
    /// receipt_trace_path). Empty (the default): nothing is stamped.
    std::function<void(const rigger_skill_SkillCommand&, std::int64_t woke_wall_ns)> on_received = {};
  };

  /// `library` is a skill-library document { "library_version": 1, "skills": [ {"name": …}, … ] }.
  /// @throws DdsError, std::invalid_argument when the library has no skills array.
  ExecutorEndpoint(const dds::Participant& participant, dds::EventLoop& loop, Logger log, std::string executor_id,
                   nlohmann::json library, Handlers handlers, Options options);
  ExecutorEndpoint(const dds::Participant& participant, dds::EventLoop& loop, Logger log, std::string executor_id,
                   nlohmann::json library, Handlers handlers)
      : ExecutorEndpoint(participant, loop, std::move(log), std::move(executor_id), std::move(library),
                         std::move(handlers), Options{}) {}
  ~ExecutorEndpoint();
  ExecutorEndpoint(const ExecutorEndpoint&) = delete;
  ExecutorEndpoint& operator=(const ExecutorEndpoint&) = delete;

  /// Reports an event of a run that is active here. Returns false (and logs) when the run is not active,
  /// or for kAccepted (the endpoint answers STARTs itself).
  /// `progress` in [0, 1], or negative when unknown.
  bool report(const LeafRun& run, EventKind kind, const std::string& code = "", const std::string& message = "",
              double progress = -1.0);

  const std::string& executor_id() const { return executor_id_; }
  /// Runs active here now.
  std::vector<LeafRun> active_runs() const;
  /// The same runs as they are announced, in (task, node) order.
  std::vector<AnnouncedRun> announced_runs() const;
  /// Publishes the announcement again (done every second, when the writer lost liveliness, and when
  /// the runs active here changed).
  void announce();

 private:
  using RunKey = std::pair<std::string, std::string>;  // (task, node)
  /// A run active here: started and not yet ended by SUCCESS, FAILURE or STOPPED.
  struct Active {
    std::uint64_t start_seq = 0;
    std::string skill;
    std::vector<std::string> resources;
    dds_instance_handle_t commander = 0;  ///< the command writer that started it
    bool stopping = false;                ///< a SHUTDOWN reached it (from the controller or from here)
    bool paused = false;                  ///< a PAUSE held it and no RESUME came yet
    bool stopped_for_pause = false;       ///< not pausable: a PAUSE brought it to its safe stop
  };
  /// A START decoded and checked, waiting for the runs that hold its node or resources to stop.
  struct Start {
    LeafRun run;
    std::string skill;
    nlohmann::json params;
    std::vector<std::string> resources;
    dds_instance_handle_t commander = 0;
    dds::EventLoop::TimerId deadline = 0;
    bool paused = false;  ///< a PAUSE came while it waited: it starts paused
  };

  /// announce(), kAnnounceDelay from now, once for all the changes meanwhile.
  void announce_soon();
  void on_commands();
  void on_commander_liveliness();
  /// The participant of a matched command writer; nothing once it is no longer matched.
  std::optional<dds_guid_t> writer_participant(dds_instance_handle_t writer) const;
  void handle(const rigger_skill_SkillCommand& cmd, const dds_sample_info_t& info);
  void handle_start(Start start);
  /// PAUSE (`pause`) or RESUME of node (task, node): answers PAUSED / RESUMED (see the file comment).
  void handle_pause(const std::string& task, const std::string& node, bool pause, const std::string& reason);
  /// Passes a PAUSE / RESUME of the active run `key` to the skill; its answer, or why it was not passed.
  PauseAnswer pause_run(const RunKey& key, bool pause, const std::string& reason);
  /// Why runs of `skill` are not paused here ("": they are: pausable, and a pause handler is set).
  std::string not_pausable(const std::string& skill) const;
  /// Why a PAUSE brings runs of `skill` holding `resources` to their safe stop instead ("": it does not:
  /// the skill pauses, or it is a monitor, or it holds no device).
  std::string stops_for_pause(const std::string& skill, const std::vector<std::string>& resources) const;
  /// Why `start` cannot run now ("" : it can); `wait` is set when every holder is being stopped.
  std::string blocked(const Start& start, bool& wait) const;
  void dispatch(Start start);
  void start_waiting();
  /// Refuses a START that runs held by a run not being stopped: ALREADY_RUNNING or RESOURCE_BUSY.
  void refuse_blocked(const Start& start, const std::string& why);
  /// Ends a START that never ran here with FAILURE `code` (the run was never active).
  void refuse(const LeafRun& run, const std::string& code, const std::string& message);
  bool write_event(const LeafRun& run, EventKind kind, const std::string& code, const std::string& message,
                   double progress);
  std::vector<std::string> resources_of(const std::string& skill, const nlohmann::json& params) const;

  dds::EventLoop& loop_;
  Logger log_;
  std::string executor_id_;
  nlohmann::json library_;
  std::string library_text_;
  std::vector<std::string> skill_names_;
  /// The library's full descriptions, parsed once: what a START claims (entries that are not full
  /// descriptions, as in tests' minimal libraries, claim nothing).
  std::map<std::string, skill::SkillDescription> descriptions_;
  Handlers handlers_;
  Options options_;
  std::string host_;
  dds::Writer<rigger_skill_ExecutorAnnouncement> announcements_;
  dds::Writer<rigger_skill_SkillEvent> events_;
  dds::Reader<rigger_skill_SkillCommand> commands_;
  std::map<dds_instance_handle_t, CommandOrder> order_by_writer_;
  std::map<RunKey, Active> active_;
  std::deque<Start> waiting_;
  std::uint64_t event_seq_ = 0;
  dds::EventLoop::TimerId refresh_timer_ = 0;
  dds::EventLoop::TimerId announce_timer_ = 0;  ///< announce_soon()'s, 0: none pending
  /// How long after a run's start, stop or end its announcement is written (announce_soon()).
  static constexpr std::chrono::milliseconds kAnnounceDelay{2};
};

/// Storage that the runs of a written announcement borrow (see rigger/dds/conversions.hpp).
struct WireRuns {
  std::vector<rigger_skill_ExecutorRun> runs;
  std::vector<std::vector<char*>> resources;
};
/// Points `announcement.runs` at `runs`, through `storage`: both must outlive the write.
void wire_runs(rigger_skill_ExecutorAnnouncement& announcement, const std::vector<AnnouncedRun>& runs,
               WireRuns& storage);
/// A temporary vector would be destroyed before the sample is written: refused at compile time.
void wire_runs(rigger_skill_ExecutorAnnouncement& announcement, const std::vector<AnnouncedRun>&& runs,
               WireRuns& storage) = delete;
/// The runs an announcement lists.
std::vector<AnnouncedRun> runs_of(const rigger_skill_ExecutorAnnouncement& announcement);

}  // namespace rigger::skill_protocol
