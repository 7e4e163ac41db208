#pragma once
/// @file
/// A skill is a finite-state machine built from the states of its activity model: query the world,
/// plan, start a primitive, await its event, verify. Each state has
///  - `on_enter`: starts the state's action; the action ends by calling transition(), succeed() or fail()
///    (at once for a synchronous primitive, from a primitive's callback for an asynchronous one);
///  - `on_shutdown`: the safe-stop action from this state (e.g. stop the robot, keep the magnet on), which
///    calls `done(true)` once the devices are safe. It is mandatory: add_state() refuses a state
///    without one, so every state has its shutdown transition.
/// A SHUTDOWN runs the current state's safe stop; the run ends STOPPED only when the safe stop reports
/// safe (else FAILURE SAFE_STOP_FAILED, so the controller escalates). Callbacks of primitives started
/// in a state are dropped once the state is left (wrap them in guard()), and the state's timers and
/// pending operations are cancelled then, so a late motion_status never drives a state it was not for.
///
/// A PAUSE (pause()) of a state with an `on_pause` hold leaves the state (its timers and operations
/// cancelled: no timeout runs out while paused) and runs the hold, which brings the state's devices to
/// rest (zero velocity; the magnet stays as it is); resume() enters the state `resume_in` (the state
/// itself by default) again, from where the devices are, its timeouts counted afresh. A state without a
/// hold (it commands no motion) runs on while paused, and the state it hands over to is entered only on
/// resume(). A hold that fails ends the run FAILURE `HOLD_FAILED` (after the state's safe stop).
/// A SHUTDOWN while paused runs the current state's safe stop as usual.
/// Thread safety: none; a skill lives on its executor's event loop thread.

#include <chrono>
#include <functional>
#include <initializer_list>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "rigger/skill_sdk/primitives.hpp"
#include "rigger/base/logging.hpp"
#include "rigger/skill/skill_description.hpp"

namespace rigger::skill_sdk {

/// How a skill run ended (what the executor reports).
struct SkillResult {
  enum class Kind { kSuccess, kFailure, kStopped };
  Kind kind = Kind::kFailure;
  std::string code;
  std::string message;
};
const char* to_string(SkillResult::Kind kind);

/// What a running skill gets from its executor. Implemented by the executor node (DDS) and by tests.
class SkillContext {
 public:
  virtual ~SkillContext() = default;
  virtual const Logger& log() const = 0;
  /// Parameters checked against the description, defaults filled, quantities in SI units.
  virtual const nlohmann::json& params() const = 0;
  /// feature_ref parameters resolved at start, by parameter name (empty when the skill has none).
  virtual const std::map<std::string, ResolvedFeature>& features() const = 0;
  virtual const Devices& devices() const = 0;
  /// Reports PROGRESS (fraction in [0, 1], or negative when unknown). Never changes the result.
  virtual void progress(double fraction, const std::string& message) = 0;
  /// One-shot timer on the executor's event loop; returns an id for cancel_timer.
  virtual std::uint64_t after(std::chrono::nanoseconds delay, std::function<void()> handler) = 0;
  virtual void cancel_timer(std::uint64_t id) = 0;
};

class Skill {
 public:
  /// Reports the end of the run, once.
  using Finished = std::function<void(const SkillResult&)>;
  /// A safe stop's completion: `safe` when the devices reached their safe state.
  using SafeStopDone = std::function<void(bool safe, const std::string& message)>;

  struct State {
    std::string name;
    std::function<void()> on_enter;
    std::function<void(SafeStopDone)> on_shutdown;
    /// The hold for a pause (see the file comment); empty: the state is not held.
    std::function<void(SafeStopDone)> on_pause = {};
    /// The state entered on resume after a hold ("": this one), e.g. the state that engages a mode.
    std::string resume_in = {};
  };

  virtual ~Skill();
  Skill(const Skill&) = delete;
  Skill& operator=(const Skill&) = delete;

  /// Binds the context and enters the first state added. `finished` is called exactly once.
  /// @throws std::logic_error when the skill has no states or was started before.
  void start(SkillContext& ctx, Finished finished);
  /// Runs the current state's safe stop; the run then ends STOPPED (or FAILURE SAFE_STOP_FAILED).
  /// Ignored when the run has ended or a safe stop is already under way.
  void shutdown(const std::string& reason);
  /// Holds the run (see the file comment); before start() it makes start() wait for resume(). Returns
  /// false when the run has ended, is stopping or is paused already.
  bool pause();
  /// Continues a paused run. Returns false when it is not paused.
  bool resume();
  bool paused() const { return paused_; }

  /// Name of the current state ("" before start; the last state after the end).
  const std::string& state() const { return current_; }
  /// Names of every state, in the order added.
  std::vector<std::string> state_names() const;
  bool finished() const { return finished_; }
  bool stopping() const { return stopping_; }
  /// The state named `name`, or nullptr. Tests use it to run every state's safe stop, including those
  /// of synchronous states the FSM never rests in.
  const State* find_state(const std::string& name) const;

 protected:
  Skill() = default;

  /// Adds a state (the first one added is the initial state). @throws std::logic_error on a missing
  /// on_enter or on_shutdown, or a duplicate name.
  void add_state(State state);
  /// Leaves the current state (cancelling its timers and operations) and enters `name`.
  /// Ignored after the end or during a safe stop. @throws std::logic_error for an unknown state.
  void transition(const std::string& name);
  void succeed(const std::string& message = "");
  void fail(const std::string& code, const std::string& message);
  /// For a skill that moved `object` where no sensor saw it (Place, CollaborativeMoveLoad): tells the
  /// world model that `object` is no longer localized (its last pose stays, marked unknown, so that nothing
  /// picks it where it was), then succeeds with `message`. Fails WORLD_UPDATE_FAILED naming what happened
  /// when the world model cannot be told. An executor without a world model succeeds at once.
  void succeed_unlocalizing(const std::string& object, const std::string& message);
  static constexpr std::chrono::seconds kWorldUpdateTimeout{2};
  /// A device the skill needs, for require_devices(): whether the executor has it, and its name in the
  /// failure (e.g. "an admittance controller").
  struct NeededDevice {
    bool present;
    const char* name;
  };
  /// Fails DEVICE_UNAVAILABLE ("this executor has no <name>") for the first of `needed` that is missing;
  /// true when none is.
  bool require_devices(std::initializer_list<NeededDevice> needed);

  /// Wraps a callback so that it runs only while the state that created it is still current (and the
  /// run has not ended or begun stopping): late events of an abandoned state are dropped.
  template <typename F>
  auto guard(F f) {
    return [this, epoch = epoch_, f = std::move(f)](auto&&... args) {
      if (epoch != epoch_ || finished_ || stopping_) return;
      f(std::forward<decltype(args)>(args)...);
    };
  }
  /// Registers a pending operation of the current state, cancelled (through `cancel`) when it is left.
  void track(std::function<void()> cancel);
  /// A timer of the current state (cancelled when it is left); the handler is guarded.
  void after(std::chrono::nanoseconds delay, std::function<void()> handler);

  /// Called by pause() and resume() of a started run (before the state is entered again): for what the
  /// skill keeps across states, e.g. a whole-run timeout that must not run out while paused.
  virtual void on_run_paused() {}
  virtual void on_run_resumed() {}

  SkillContext& ctx() const { return *ctx_; }
  const nlohmann::json& params() const { return ctx_->params(); }

 private:
  void enter(std::size_t index);
  void leave_state();
  void finish(SkillResult result);

  std::vector<State> states_;
  std::string current_;
  std::size_t current_index_ = 0;
  std::uint64_t epoch_ = 0;
  std::vector<std::function<void()>> pending_cancels_;
  SkillContext* ctx_ = nullptr;
  Finished finished_cb_;
  bool started_ = false;
  bool finished_ = false;
  bool stopping_ = false;
  bool in_enter_ = false;
  std::optional<std::size_t> deferred_;  // a transition requested inside on_enter
  bool paused_ = false;
  std::optional<std::size_t> on_resume_;  // the state resume() enters (after a hold, or a transition while paused)
};

/// A safe stop with nothing to do (the state commands no device): done(true) at once.
void nothing_to_stop(const Skill::SafeStopDone& done);

}  // namespace rigger::skill_sdk
