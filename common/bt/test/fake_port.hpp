#pragma once
// A Port for engine tests: fake time, a log of every call, and helpers to drive an Engine.

#include <algorithm>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "rigger/bt/engine.hpp"
#include "rigger/bt/tree_builder.hpp"

namespace rigger::bt::testing {

class FakePort : public Port {
 public:
  TimePoint now() override { return now_; }

  void start_leaf(const NodeSpec& node, Activation activation) override {
    log_.push_back("start " + node.id);
    starts_.push_back(node.id);
    (void)activation;
  }
  void shutdown_leaf(const NodeSpec& node, Activation /*activation*/, const std::string& reason) override {
    log_.push_back("shutdown " + node.id);
    shutdowns_.push_back(node.id);
    last_shutdown_reason_ = reason;
  }
  void evaluate_condition(const NodeSpec& node, Activation /*activation*/) override {
    log_.push_back("evaluate " + node.id);
  }
  void ask_operator(const NodeSpec& node, Activation /*activation*/) override { log_.push_back("ask " + node.id); }
  void withdraw_operator_request(const NodeSpec& node, Activation /*activation*/) override {
    log_.push_back("withdraw " + node.id);
  }
  void schedule(TimerId id, TimePoint deadline) override { timers_[id] = deadline; }
  void cancel_timer(TimerId id) override { timers_.erase(id); }
  void escalate_safe_stop(const NodeSpec& node, const std::string& /*why*/) override {
    log_.push_back("escalate " + node.id);
    escalations_.push_back(node.id);
  }
  void node_changed(const NodeSpec& node, const NodeStatus& status) override {
    log_.push_back("state " + node.id + " " + std::string(to_string(status.state)));
    ++changes_;
  }
  void finished(const TaskResult& result) override {
    log_.push_back("finished " + std::string(to_string(result.outcome)));
    ++finished_count_;
    result_ = result;
  }

  /// Moves time forward, firing due timers in deadline order through `engine`.
  void advance(Engine& engine, Seconds by) {
    const TimePoint target = now_ + std::chrono::duration_cast<Clock::duration>(by);
    while (true) {
      auto next = std::min_element(timers_.begin(), timers_.end(),
                                   [](const auto& a, const auto& b) { return a.second < b.second; });
      if (next == timers_.end() || next->second > target) {
        break;
      }
      const TimerId id = next->first;
      now_ = std::max(now_, next->second);
      timers_.erase(next);
      const auto r = engine.on_timer(id);
      EXPECT_TRUE(r.acted_on()) << r.reason;
    }
    now_ = target;
  }

  const std::vector<std::string>& log() const { return log_; }
  const std::vector<std::string>& starts() const { return starts_; }
  const std::vector<std::string>& shutdowns() const { return shutdowns_; }
  const std::vector<std::string>& escalations() const { return escalations_; }
  const std::map<TimerId, TimePoint>& timers() const { return timers_; }
  const std::optional<TaskResult>& result() const { return result_; }
  int finished_count() const { return finished_count_; }
  std::size_t changes() const { return changes_; }
  const std::string& last_shutdown_reason() const { return last_shutdown_reason_; }

  /// Position of the first log entry equal to `entry`, or -1.
  long position(const std::string& entry) const {
    const auto it = std::find(log_.begin(), log_.end(), entry);
    return it == log_.end() ? -1 : static_cast<long>(it - log_.begin());
  }
  std::size_t count(const std::string& entry) const {
    return static_cast<std::size_t>(std::count(log_.begin(), log_.end(), entry));
  }
  void clear_log() {
    log_.clear();
    starts_.clear();
    shutdowns_.clear();
  }

 private:
  TimePoint now_{std::chrono::seconds(1000)};
  std::vector<std::string> log_;
  std::vector<std::string> starts_;
  std::vector<std::string> shutdowns_;
  std::vector<std::string> escalations_;
  std::map<TimerId, TimePoint> timers_;
  std::optional<TaskResult> result_;
  int finished_count_ = 0;
  std::size_t changes_ = 0;
  std::string last_shutdown_reason_;
};

/// An engine on a fake port with shorthand for the events tests send.
struct Harness {
  explicit Harness(const build::Node& root) : engine(std::make_unique<Engine>(build::build(root), port)) {}
  explicit Harness(TreeSpec spec) : engine(std::make_unique<Engine>(std::move(spec), port)) {}

  NodeIndex index(const std::string& id) const {
    const auto found = engine->find(id);
    EXPECT_TRUE(found.has_value()) << id;
    return found.value_or(0);
  }
  Activation act(const std::string& id) const { return engine->status(index(id)).activation; }
  NodeState state(const std::string& id) const { return engine->status(index(id)).state; }
  const NodeStatus& status(const std::string& id) const { return engine->status(index(id)); }

  EventResult leaf(const std::string& id, LeafEventKind kind, const std::string& code = "") {
    LeafEvent e;
    e.kind = kind;
    e.activation = act(id);
    e.code = code;
    e.message = code.empty() ? "" : "because " + code;
    return engine->on_leaf_event(id, e);
  }
  EventResult succeed(const std::string& id) { return leaf(id, LeafEventKind::kSuccess); }
  EventResult fail(const std::string& id, const std::string& code = "BROKEN") {
    return leaf(id, LeafEventKind::kFailure, code);
  }
  EventResult stopped(const std::string& id) { return leaf(id, LeafEventKind::kStopped); }
  EventResult condition(const std::string& id, bool holds) { return engine->on_condition_result(id, act(id), holds); }
  EventResult decide(const std::string& id, std::size_t option) {
    return engine->on_operator_decision(id, act(id), option);
  }
  void advance(double seconds) { port.advance(*engine, Seconds(seconds)); }

  /// Answers STOPPED for every leaf currently STOPPING.
  void stop_all_stopping() {
    for (NodeIndex i = 0; i < engine->spec().nodes.size(); ++i) {
      if (engine->status(i).state == NodeState::kStopping && is_remote_leaf(engine->spec().nodes[i].kind)) {
        const auto r = stopped(engine->spec().nodes[i].id);
        EXPECT_TRUE(r.acted_on()) << r.reason;
      }
    }
  }

  FakePort port;
  std::unique_ptr<Engine> engine;
};

}  // namespace rigger::bt::testing
