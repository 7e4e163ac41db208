#pragma once
/// @file
/// The executor side of the skill protocol. An executor announces what it offers on
/// rigger/skill/executors (liveliness-monitored, so the controller sees it die or hang), receives the
/// SkillCommands addressed to it on rigger/skill/command, and reports SkillEvents on rigger/skill/event.
///
/// Protocol rules enforced here, so that no skill has to:
///  - commands for other executors are ignored; a command whose seq is not newer than the last one from
///    the same controller is a duplicate or stale and is dropped (logged);
///  - START with unparsable params → FAILURE `BAD_PARAMS`; for a skill not in the library →
///    FAILURE `UNKNOWN_SKILL`; for a node that already runs here → dropped (logged);
///  - SHUTDOWN for a node that does not run here → STOPPED `NOT_RUNNING` at once (it ended, or never
///    started), so the controller never waits for a stop timeout because of a race;
///  - every event carries a per-executor seq and the seq of the START it belongs to (`start_seq`);
///    after SUCCESS, FAILURE or STOPPED the run is over and further reports for it are dropped.
/// All callbacks run on the service's event loop thread.

#include <cstdint>
#include <functional>
#include <map>
#include <string>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

#include "rigger/base/logging.hpp"
#include "rigger/dds/event_loop.hpp"
#include "rigger/dds/pubsub.hpp"

namespace rigger::executor {

/// One run of a leaf. The START's seq tells a re-run of the same node (Retry, Repeat) from the last one.
struct LeafRun {
  std::string task_id;
  std::string node_id;
  std::uint64_t start_seq = 0;
};

enum class EventKind { kSuccess, kFailure, kStopped, kProgress };

struct StartRequest {
  LeafRun run;
  std::string skill;
  nlohmann::json params;  ///< an object; the controller has validated and filled defaults
};

struct ShutdownRequest {
  LeafRun run;
  std::string reason;
};

class ExecutorEndpoint {
 public:
  struct Handlers {
    std::function<void(const StartRequest&)> on_start;
    std::function<void(const ShutdownRequest&)> on_shutdown;
  };

  /// `library` is a skill-library document { "library_version": 1, "skills": [ {"name": …}, … ] }.
  /// @throws DdsError, std::invalid_argument when the library has no skills array.
  ExecutorEndpoint(const dds::Participant& participant, dds::EventLoop& loop, Logger log, std::string executor_id,
                   nlohmann::json library, Handlers handlers);
  ~ExecutorEndpoint();
  ExecutorEndpoint(const ExecutorEndpoint&) = delete;
  ExecutorEndpoint& operator=(const ExecutorEndpoint&) = delete;

  /// Reports an event of a run that is active here. Returns false (and logs) when the run is not active.
  /// `progress` in [0, 1], or negative when unknown.
  bool report(const LeafRun& run, EventKind kind, const std::string& code = "", const std::string& message = "",
              double progress = -1.0);

  const std::string& executor_id() const { return executor_id_; }
  /// Runs active here now.
  std::vector<LeafRun> active_runs() const;
  /// Publishes the announcement again (done every second and when the writer lost liveliness).
  void announce();

 private:
  void on_commands();
  void handle(const rigger_skill_SkillCommand& cmd, const dds_sample_info_t& info);

  dds::EventLoop& loop_;
  Logger log_;
  std::string executor_id_;
  nlohmann::json library_;
  std::string library_text_;
  std::vector<std::string> skill_names_;
  Handlers handlers_;
  std::string host_;
  dds::Writer<rigger_skill_ExecutorAnnouncement> announcements_;
  dds::Writer<rigger_skill_SkillEvent> events_;
  dds::Reader<rigger_skill_SkillCommand> commands_;
  std::map<dds_instance_handle_t, std::uint64_t> last_seq_by_writer_;
  std::map<std::pair<std::string, std::string>, std::uint64_t> active_;  // (task, node) -> start seq
  std::uint64_t event_seq_ = 0;
  dds::EventLoop::TimerId refresh_timer_ = 0;
};

const char* to_string(EventKind kind);

}  // namespace rigger::executor
