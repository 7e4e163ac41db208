#include "rigger/skill_sdk/skill.hpp"

#include "rigger/skill_sdk/cell_devices.hpp"

#include <stdexcept>

namespace rigger::skill_sdk {

const char* to_string(SkillResult::Kind kind) {
  switch (kind) {
    case SkillResult::Kind::kSuccess:
      return "SUCCESS";
    case SkillResult::Kind::kFailure:
      return "FAILURE";
    case SkillResult::Kind::kStopped:
      return "STOPPED";
  }
  return "?";
}

void nothing_to_stop(const Skill::SafeStopDone& done) { done(true, "nothing to stop"); }

Skill::~Skill() { leave_state(); }

void Skill::add_state(State state) {
  if (state.name.empty()) throw std::logic_error("a skill state needs a name");
  if (!state.on_enter) throw std::logic_error("skill state '" + state.name + "' has no on_enter");
  if (!state.on_shutdown) throw std::logic_error("skill state '" + state.name + "' has no on_shutdown (safe stop)");
  for (const auto& s : states_)
    if (s.name == state.name) throw std::logic_error("duplicate skill state '" + state.name + "'");
  states_.push_back(std::move(state));
}

std::vector<std::string> Skill::state_names() const {
  std::vector<std::string> names;
  for (const auto& s : states_) names.push_back(s.name);
  return names;
}

const Skill::State* Skill::find_state(const std::string& name) const {
  for (const auto& s : states_)
    if (s.name == name) return &s;
  return nullptr;
}

void Skill::start(SkillContext& ctx, Finished finished) {
  if (started_) throw std::logic_error("skill started twice");
  if (states_.empty()) throw std::logic_error("skill has no states");
  started_ = true;
  ctx_ = &ctx;
  finished_cb_ = std::move(finished);
  if (paused_) {  // paused before it started: the first state waits for resume()
    on_resume_ = 0;
    return;
  }
  enter(0);
}

void Skill::enter(std::size_t index) {
  // A state's on_enter may transition at once (a synchronous primitive); the loop enters the next
  // state after the current on_enter returned instead of recursing.
  deferred_ = index;
  if (in_enter_) return;
  while (deferred_ && !finished_ && !stopping_) {
    const std::size_t next = *deferred_;
    deferred_.reset();
    leave_state();
    if (paused_) {  // the state that ran on while paused has ended: the next one waits for resume()
      on_resume_ = next;
      return;
    }
    current_index_ = next;
    current_ = states_[next].name;
    ctx_->log()->debug("skill state -> {}", current_);
    in_enter_ = true;
    try {
      states_[next].on_enter();
    } catch (const std::exception& e) {
      in_enter_ = false;
      deferred_.reset();
      fail("SKILL_ERROR", "state '" + current_ + "' threw: " + e.what());
      return;
    }
    in_enter_ = false;
  }
}

void Skill::transition(const std::string& name) {
  if (finished_ || stopping_) return;
  for (std::size_t i = 0; i < states_.size(); ++i) {
    if (states_[i].name == name) {
      enter(i);
      return;
    }
  }
  throw std::logic_error("unknown skill state '" + name + "'");
}

void Skill::leave_state() {
  ++epoch_;
  auto cancels = std::move(pending_cancels_);
  pending_cancels_.clear();
  for (auto& cancel : cancels) cancel();
}

void Skill::track(std::function<void()> cancel) { pending_cancels_.push_back(std::move(cancel)); }

void Skill::after(std::chrono::nanoseconds delay, std::function<void()> handler) {
  const auto id = ctx_->after(delay, guard(std::move(handler)));
  track([this, id] { ctx_->cancel_timer(id); });
}

bool Skill::pause() {
  if (finished_ || stopping_ || paused_) return false;
  paused_ = true;
  if (!started_) return true;
  on_run_paused();
  if (on_resume_) return true;
  const State& state = states_[current_index_];
  if (!state.on_pause) return true;  // runs on; the next state waits (enter())
  std::size_t resume_index = current_index_;
  for (std::size_t i = 0; i < states_.size(); ++i)
    if (!state.resume_in.empty() && states_[i].name == state.resume_in) resume_index = i;
  on_resume_ = resume_index;
  leave_state();  // its timers and operations: nothing runs out, no late event drives it
  ctx_->log()->info("skill paused in state {}: holding", current_);
  state.on_pause([this, epoch = epoch_](bool safe, const std::string& message) {
    if (epoch != epoch_ || finished_ || stopping_) return;  // resumed (or ended) meanwhile
    if (!safe) fail("HOLD_FAILED", "the pause could not hold the devices in state " + current_ + ": " + message);
  });
  return true;
}

bool Skill::resume() {
  if (!paused_) return false;
  paused_ = false;
  if (finished_ || stopping_ || !started_) return true;
  on_run_resumed();
  if (!on_resume_) return true;
  const std::size_t next = *on_resume_;
  on_resume_.reset();
  ctx_->log()->info("skill resumed: entering state {}", states_[next].name);
  enter(next);
  return true;
}

void Skill::succeed(const std::string& message) {
  if (finished_ || stopping_) return;
  finish({SkillResult::Kind::kSuccess, "", message});
}

bool Skill::require_devices(std::initializer_list<NeededDevice> needed) {
  for (const NeededDevice& device : needed) {
    if (device.present) continue;
    fail("DEVICE_UNAVAILABLE", std::string("this executor has no ") + device.name);
    return false;
  }
  return true;
}

void Skill::succeed_unlocalizing(const std::string& object, const std::string& message) {
  WorldAccess* world = ctx().devices().world_access;
  if (world == nullptr) {
    succeed(message);
    return;
  }
  ctx().progress(0.98, "telling the world model that " + object + " moved unobserved");
  const OpId id = world->mark_unlocalized(
      object, std::chrono::system_clock::now(), kWorldUpdateTimeout, guard([this, object, message](const OpResult& r) {
        if (r.ok)
          succeed(message + "; " + object + " no longer localized");
        else
          fail("WORLD_UPDATE_FAILED", message + ", but the world model could not be told that " + object +
                                          " moved (it still holds the old pose): " + r.code + ": " + r.message);
      }));
  track([world, id] { world->cancel(id); });
}

void Skill::fail(const std::string& code, const std::string& message) {
  if (finished_ || stopping_) return;
  // A failure mid-action leaves devices as the state left them: bring them to the state's safe stop
  // first, then report, so that a FAILURE never leaves a motion running.
  stopping_ = true;
  leave_state();
  states_[current_index_].on_shutdown([this, code, message](bool safe, const std::string& stop_message) {
    if (finished_) return;
    finish({SkillResult::Kind::kFailure, code,
            safe ? message : message + " (and the safe stop failed: " + stop_message + ")"});
  });
}

void Skill::shutdown(const std::string& reason) {
  if (!started_ || finished_ || stopping_) return;
  stopping_ = true;
  leave_state();
  ctx_->log()->info("skill shutdown in state {}: {}", current_, reason);
  states_[current_index_].on_shutdown([this](bool safe, const std::string& message) {
    if (finished_) return;
    if (safe) finish({SkillResult::Kind::kStopped, "", "safe stop reached in state " + current_ + ": " + message});
    else finish({SkillResult::Kind::kFailure, "SAFE_STOP_FAILED", "safe stop failed in state " + current_ + ": " + message});
  });
}

void Skill::finish(SkillResult result) {
  if (finished_) return;
  finished_ = true;
  leave_state();
  if (finished_cb_) finished_cb_(result);
}

}  // namespace rigger::skill_sdk
