#pragma once
// Fake primitives and timers for unit tests of skill FSMs: every operation is recorded and completed
// by the test, and time moves only when the test advances it.

#include <map>
#include <optional>
#include <vector>

#include "rigger/skill_sdk/primitives.hpp"
#include "rigger/skill_sdk/skill_run.hpp"

namespace rigger::skill_sdk::testing {

class FakeTimers final : public Timers {
 public:
  std::uint64_t after(std::chrono::nanoseconds delay, std::function<void()> handler) override {
    const auto id = ++next_;
    timers_[id] = {now_ + delay, std::move(handler)};
    return id;
  }
  void cancel(std::uint64_t id) override { timers_.erase(id); }
  /// Moves time on by `d`, firing due timers in deadline order.
  void advance(std::chrono::nanoseconds d) {
    const auto until = now_ + d;
    for (;;) {
      auto next = timers_.end();
      for (auto it = timers_.begin(); it != timers_.end(); ++it)
        if (it->second.first <= until && (next == timers_.end() || it->second.first < next->second.first)) next = it;
      if (next == timers_.end()) break;
      now_ = next->second.first;
      auto fn = std::move(next->second.second);
      timers_.erase(next);
      fn();
    }
    now_ = until;
  }
  std::size_t pending() const { return timers_.size(); }

 private:
  std::chrono::nanoseconds now_{0};
  std::uint64_t next_ = 0;
  std::map<std::uint64_t, std::pair<std::chrono::nanoseconds, std::function<void()>>> timers_;
};

class FakeRobot final : public RobotMotion {
 public:
  struct Op {
    enum class Kind { kMove, kStop, kState } kind;
    MotionGoal goal;
    std::chrono::nanoseconds timeout;
    OpCallback done;
    std::function<void(std::optional<RobotSnapshot>)> state_done;
  };
  OpId move(const MotionGoal& goal, std::chrono::nanoseconds timeout, OpCallback done) override {
    ops_[++next_] = {Op::Kind::kMove, goal, timeout, std::move(done), {}};
    ++moves;
    return next_;
  }
  OpId stop(std::chrono::nanoseconds timeout, OpCallback done) override {
    ops_[++next_] = {Op::Kind::kStop, {}, timeout, std::move(done), {}};
    ++stops;
    return next_;
  }
  OpId next_state(std::chrono::nanoseconds timeout, std::function<void(std::optional<RobotSnapshot>)> done) override {
    ops_[++next_] = {Op::Kind::kState, {}, timeout, {}, std::move(done)};
    return next_;
  }
  void cancel(OpId id) override {
    if (ops_.erase(id)) ++cancels;
  }
  /// The pending operation of `kind` (the newest), or nullptr.
  Op* pending(Op::Kind kind) {
    for (auto it = ops_.rbegin(); it != ops_.rend(); ++it)
      if (it->second.kind == kind) return &it->second;
    return nullptr;
  }
  /// Completes the newest pending operation of `kind` with `result`; false when none is pending.
  bool complete(Op::Kind kind, const OpResult& result) {
    for (auto it = ops_.rbegin(); it != ops_.rend(); ++it) {
      if (it->second.kind != kind) continue;
      auto done = std::move(it->second.done);
      ops_.erase(std::next(it).base());
      done(result);
      return true;
    }
    return false;
  }
  bool answer_state(std::optional<RobotSnapshot> state) {
    for (auto it = ops_.rbegin(); it != ops_.rend(); ++it) {
      if (it->second.kind != Op::Kind::kState) continue;
      auto done = std::move(it->second.state_done);
      ops_.erase(std::next(it).base());
      done(std::move(state));
      return true;
    }
    return false;
  }
  int moves = 0, stops = 0, cancels = 0;

 private:
  std::map<OpId, Op> ops_;
  OpId next_ = 0;
};

class FakeResolver final : public FeatureResolver {
 public:
  struct Request {
    std::string ref, frame;
    std::function<void(const OpResult&, const ResolvedFeature&)> done;
  };
  OpId resolve(const std::string& ref, const std::string& frame, std::chrono::nanoseconds,
               std::function<void(const OpResult&, const ResolvedFeature&)> done) override {
    requests_[++next_] = {ref, frame, std::move(done)};
    return next_;
  }
  void cancel(OpId id) override { requests_.erase(id); }
  /// Answers the oldest pending request.
  bool answer(const OpResult& result, const Eigen::Isometry3d& pose = Eigen::Isometry3d::Identity()) {
    if (requests_.empty()) return false;
    auto it = requests_.begin();
    auto req = std::move(it->second);
    requests_.erase(it);
    ResolvedFeature f{req.ref, req.frame, pose, localized, 0.1};
    req.done(result, f);
    return true;
  }
  std::size_t pending() const { return requests_.size(); }
  bool localized = true;  ///< what answer() reports
  const Request* oldest() const { return requests_.empty() ? nullptr : &requests_.begin()->second; }

 private:
  std::map<OpId, Request> requests_;
  OpId next_ = 0;
};

/// The gripper: set_energized and wait_state are recorded; the test confirms commands (`confirm`)
/// and publishes state samples (`publish`), which end every pending wait whose predicate they satisfy.
class FakeGripper final : public Gripper {
 public:
  struct Command {
    bool energize = false;
    std::chrono::nanoseconds timeout{0};
    OpCallback done;
  };
  struct Wait {
    std::function<bool(const GripperSnapshot&)> predicate;
    std::chrono::nanoseconds timeout{0};
    StateCallback done;
  };
  OpId set_energized(bool energize, std::chrono::nanoseconds timeout, OpCallback done) override {
    commands_[++next_] = {energize, timeout, std::move(done)};
    commanded.push_back(energize);
    return next_;
  }
  OpId wait_state(std::function<bool(const GripperSnapshot&)> predicate, std::chrono::nanoseconds timeout,
                  StateCallback done) override {
    waits_[++next_] = {std::move(predicate), timeout, std::move(done)};
    return next_;
  }
  void cancel(OpId id) override {
    if (commands_.erase(id) + waits_.erase(id)) ++cancels;
  }
  /// The newest pending set_energized, or nullptr.
  const Command* pending_command() const { return commands_.empty() ? nullptr : &commands_.rbegin()->second; }
  /// Completes the newest pending set_energized; false when none is pending.
  bool confirm(const OpResult& result = OpResult::success()) {
    if (commands_.empty()) return false;
    auto it = std::prev(commands_.end());
    auto done = std::move(it->second.done);
    commands_.erase(it);
    done(result);
    return true;
  }
  /// Offers a state sample to the pending waits; returns how many it ended.
  int publish(const GripperSnapshot& state) {
    std::vector<StateCallback> ready;
    for (auto it = waits_.begin(); it != waits_.end();) {
      if (it->second.predicate(state)) {
        ready.push_back(std::move(it->second.done));
        it = waits_.erase(it);
      } else {
        ++it;
      }
    }
    for (auto& done : ready) done(state);
    return static_cast<int>(ready.size());
  }
  /// Ends the oldest pending wait with std::nullopt (its timeout); false when none is pending.
  bool time_out_wait() {
    if (waits_.empty()) return false;
    auto it = waits_.begin();
    auto done = std::move(it->second.done);
    waits_.erase(it);
    done(std::nullopt);
    return true;
  }
  std::size_t pending_waits() const { return waits_.size(); }
  const Wait* oldest_wait() const { return waits_.empty() ? nullptr : &waits_.begin()->second; }

  static GripperSnapshot state(bool energized, bool holding, bool contact = false) {
    GripperSnapshot g;
    g.energized = energized;
    g.holding = holding;
    g.contact = contact || holding;
    return g;
  }

  std::vector<bool> commanded;  ///< every set_energized, in order
  int cancels = 0;

 private:
  std::map<OpId, Command> commands_;
  std::map<OpId, Wait> waits_;
  OpId next_ = 0;
};

}  // namespace rigger::skill_sdk::testing
