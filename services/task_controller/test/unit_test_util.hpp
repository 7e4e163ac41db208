#pragma once
// Shared by the controller's unit tests: skill-library documents cut from the scripted library, and a
// bt::Port that journals NODE rows as Task::node_changed does (for the resume tests).

#include <fstream>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "journal.hpp"
#include "rigger/bt/engine.hpp"

namespace rigger::task_controller::testing {

/// test/data/scripted_skill_library.json (what the scripted executor announces) with only `names`.
inline nlohmann::json library_with(const std::vector<std::string>& names) {
  std::ifstream in(std::string(RIGGER_SOURCE_DIR) + "/test/data/scripted_skill_library.json");
  const nlohmann::json all = nlohmann::json::parse(in);
  nlohmann::json out = all;
  out["skills"] = nlohmann::json::array();
  for (const auto& s : all.at("skills"))
    for (const auto& n : names)
      if (s.at("name") == n) out["skills"].push_back(s);
  return out;
}

/// A Port that keeps the journal's NODE rows (written as Task::node_changed writes them) and the STARTs,
/// shutdowns and questions, nothing else.
class JournalingPort : public bt::Port {
 public:
  bt::TimePoint now() override { return bt::TimePoint{}; }
  void start_leaf(const bt::NodeSpec& n, bt::Activation) override { starts.push_back(n.id); }
  void shutdown_leaf(const bt::NodeSpec& n, bt::Activation, const std::string&) override { shutdowns.push_back(n.id); }
  void evaluate_condition(const bt::NodeSpec& n, bt::Activation) override { starts.push_back(n.id); }
  void ask_operator(const bt::NodeSpec& n, bt::Activation) override { asked.push_back(n.id); }
  void withdraw_operator_request(const bt::NodeSpec&, bt::Activation) override {}
  void schedule(bt::TimerId, bt::TimePoint) override {}
  void cancel_timer(bt::TimerId) override {}
  void escalate_safe_stop(const bt::NodeSpec&, const std::string&) override {}
  void node_changed(const bt::NodeSpec& n, const bt::NodeStatus& s) override {
    if (s.state == bt::NodeState::kRunning && s.progress) return;
    rows.push_back({0, "t", n.id, "NODE", std::string(bt::to_string(s.state)),
                    s.code.empty() ? s.message : s.code + ": " + s.message});
  }
  void finished(const bt::TaskResult& r) override { result = r; }

  std::vector<JournalRecord> rows;
  std::vector<std::string> starts, shutdowns, asked;
  std::optional<bt::TaskResult> result;
};

}  // namespace rigger::task_controller::testing
