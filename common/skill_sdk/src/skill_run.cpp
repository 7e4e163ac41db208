#include "rigger/skill_sdk/skill_run.hpp"

#include "rigger/skill/param_check.hpp"

namespace rigger::skill_sdk {

SkillRun::SkillRun(const SkillType& type, nlohmann::json params, Devices devices, Timers& timers, Logger log,
                   Callbacks callbacks, Options options)
    : type_(type),
      raw_params_(std::move(params)),
      devices_(devices),
      timers_(timers),
      log_(std::move(log)),
      callbacks_(std::move(callbacks)),
      options_(std::move(options)) {}

SkillRun::~SkillRun() {
  if (resolving_ != 0 && devices_.world) devices_.world->cancel(resolving_);
  skill_.reset();  // cancels the current state's timers and operations
}

void SkillRun::start() {
  const auto checked = skill::check_params(type_.description, raw_params_, "/params");
  if (!checked.ok()) {
    std::string text;
    for (const auto& e : checked.errors) text += (text.empty() ? "" : "; ") + e.to_string();
    finish({SkillResult::Kind::kFailure, "BAD_PARAMS", text});
    return;
  }
  params_ = checked.params;
  for (const auto& spec : type_.description.params)
    if (spec.type == skill::ParamType::kFeatureRef && params_.contains(spec.name) && params_[spec.name].is_string())
      to_resolve_.push_back(spec.name);
  if (!to_resolve_.empty() && !devices_.world) {
    finish({SkillResult::Kind::kFailure, "DEVICE_UNAVAILABLE",
            "parameter /params/" + to_resolve_.front() + " names a world-model feature, but this executor has no world model"});
    return;
  }
  resolve_next();
}

void SkillRun::resolve_next() {
  if (finished_) return;
  if (shutdown_requested_) {  // nothing has moved yet: the safe state is where we are
    finish({SkillResult::Kind::kStopped, "", "stopped while resolving parameters"});
    return;
  }
  if (to_resolve_.empty()) {
    start_skill();
    return;
  }
  const std::string name = to_resolve_.back();
  to_resolve_.pop_back();
  const std::string ref = params_[name].get<std::string>();
  resolving_ = devices_.world->resolve(
      ref, options_.resolve_frame, options_.resolve_timeout,
      [this, name, ref](const OpResult& result, const ResolvedFeature& feature) {
        resolving_ = 0;
        if (finished_) return;
        if (!result.ok) {
          finish({SkillResult::Kind::kFailure, result.code.empty() ? "UNKNOWN_FEATURE" : result.code,
                  "/params/" + name + " = \"" + ref + "\": " + result.message});
          return;
        }
        features_[name] = feature;
        resolve_next();
      });
}

void SkillRun::start_skill() {
  skill_ = type_.make();
  if (pause_requested_) skill_->pause();  // paused while its parameters were resolved
  skill_->start(*this, [this](const SkillResult& result) { finish(result); });
}

void SkillRun::shutdown(const std::string& reason) {
  if (finished_) return;
  if (skill_) {
    skill_->shutdown(reason);
    return;
  }
  // Still resolving parameters: no device was commanded yet.
  shutdown_requested_ = true;
  if (resolving_ != 0) {
    devices_.world->cancel(resolving_);
    resolving_ = 0;
  }
  resolve_next();
}

bool SkillRun::pause(bool hold) {
  if (finished_) return false;
  if (skill_) return hold ? skill_->pause() : skill_->resume();
  // Still resolving parameters (nothing moves): the skill starts paused, or not.
  if (pause_requested_ == hold) return false;
  pause_requested_ = hold;
  return true;
}

void SkillRun::progress(double fraction, const std::string& message) {
  if (!finished_ && callbacks_.progress) callbacks_.progress(fraction, message);
}

std::uint64_t SkillRun::after(std::chrono::nanoseconds delay, std::function<void()> handler) {
  return timers_.after(delay, std::move(handler));
}

void SkillRun::cancel_timer(std::uint64_t id) { timers_.cancel(id); }

void SkillRun::finish(const SkillResult& result) {
  if (finished_) return;
  finished_ = true;
  log_->info("skill {} ended {} code={} {}", type_.description.name, to_string(result.kind), result.code, result.message);
  if (callbacks_.finished) callbacks_.finished(result);
}

}  // namespace rigger::skill_sdk
