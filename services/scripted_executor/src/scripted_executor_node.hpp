#pragma once
/// @file
/// The scripted executor's node: announces a skill library through ExecutorEndpoint and plays a
/// Behaviour (behaviour.hpp) for every START.
///
/// Configuration keys: scripted_executor_settings() (rigger/scripted_executor/settings.hpp).

#include <cstdint>
#include <map>
#include <string>
#include <utility>
#include <vector>

#include "behaviour.hpp"
#include "rigger/service/service.hpp"
#include "rigger/skill_protocol/executor_endpoint.hpp"
#include "scripted_settings.hpp"

namespace rigger::scripted {

class ScriptedExecutorNode : public service::Node {
 public:
  /// @throws ConfigError, DdsError.
  explicit ScriptedExecutorNode(service::ServiceContext& ctx);
  ~ScriptedExecutorNode() override;

 private:
  struct Active {
    skill_protocol::LeafRun run;
    Behaviour behaviour;
    std::vector<dds::EventLoop::TimerId> timers;
    bool stopping = false;
  };
  using Key = std::pair<std::string, std::string>;  // task, node

  void on_start(const skill_protocol::StartRequest& request);
  void on_shutdown(const skill_protocol::ShutdownRequest& request);
  void finish(const Key& key, skill_protocol::EventKind kind, std::string code, std::string message);
  const Behaviour& behaviour_for(const std::string& skill, const std::string& node_id) const;

  /// The receipt trace's kind of an event this executor wrote: this + skill_protocol::EventKind (a
  /// command's kind is its SkillCommandKind, below it).
  static constexpr int kEventKindBase = 100;
  /// One command taken or event written (receipt_trace_path): for benchmarks that time a command's way
  /// to its executor, and the hand-over from an event to the command it causes.
  struct Receipt {
    std::string executor_id;  ///< whom the command names (an event: this executor)
    int kind = 0;             ///< rigger_skill_SkillCommandKind, or kEventKindBase + the event's kind
    std::string task_id;
    std::string node_id;
    std::int64_t stamp_wall_ns = 0;  ///< the controller's stamp (an event: as it was written)
    std::int64_t woke_wall_ns = 0;   ///< when this executor's command handler began (an event: its stamp)
  };

  service::ServiceContext& ctx_;
  std::string receipt_trace_path_;  ///< empty: no receipt trace
  std::vector<Receipt> receipts_;
  std::map<std::string, Behaviour> by_skill_;
  std::map<std::string, Behaviour> by_node_;
  Behaviour default_skill_;
  Behaviour default_monitor_;
  std::map<std::string, bool> is_monitor_;
  std::map<Key, Active> active_;
  std::unique_ptr<skill_protocol::ExecutorEndpoint> endpoint_;
};

}  // namespace rigger::scripted
