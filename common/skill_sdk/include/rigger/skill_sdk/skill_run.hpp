#pragma once
/// @file
/// One run of a skill, without DDS: checks the START's params against the description (defaults,
/// units), resolves its feature_ref params through the FeatureResolver, starts the skill's FSM, relays
/// its progress and result, and turns a SHUTDOWN into the current state's safe stop. The executor node
/// owns one SkillRun per running leaf; tests drive it with fake devices and fake timers.
///
/// Failure codes of the run itself: BAD_PARAMS (message lists every error with its pointer),
/// DEVICE_UNAVAILABLE (a feature_ref param but no world model configured), the resolver's code
/// (e.g. UNKNOWN_FEATURE, WORLD_UNREACHABLE) prefixed by nothing, and SKILL_ERROR (a state threw).
///
/// Thread safety: none; the executor's event loop thread.

#include <chrono>
#include <functional>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "rigger/skill_sdk/skill.hpp"
#include "rigger/skill_sdk/skill_registry.hpp"

namespace rigger::skill_sdk {

/// Timers on the executor's clock (the EventLoop, or a fake in tests).
class Timers {
 public:
  virtual ~Timers() = default;
  virtual std::uint64_t after(std::chrono::nanoseconds delay, std::function<void()> handler) = 0;
  virtual void cancel(std::uint64_t id) = 0;
};

class SkillRun final : public SkillContext {
 public:
  struct Callbacks {
    std::function<void(double fraction, const std::string& message)> progress;
    /// Called once; the run may be destroyed after it returns (not inside it).
    std::function<void(const SkillResult&)> finished;
  };
  struct Options {
    std::string resolve_frame = "world";  ///< frame feature_ref params are resolved in
    std::chrono::nanoseconds resolve_timeout = std::chrono::seconds(2);
  };

  SkillRun(const SkillType& type, nlohmann::json params, Devices devices, Timers& timers, Logger log,
           Callbacks callbacks, Options options);
  SkillRun(const SkillType& type, nlohmann::json params, Devices devices, Timers& timers, Logger log,
           Callbacks callbacks)
      : SkillRun(type, std::move(params), devices, timers, std::move(log), std::move(callbacks), Options{}) {}
  ~SkillRun() override;

  /// Checks params, resolves features, starts the FSM. Ends through `finished` (maybe at once).
  void start();
  /// Safe stop from wherever the run is; STOPPED once safe.
  void shutdown(const std::string& reason);
  /// PAUSE (`hold`) or RESUME of the run (Skill::pause / resume; while parameters are resolved, the
  /// skill starts paused). Returns false when the run has ended, or was already in that state.
  bool pause(bool hold);

  bool finished() const { return finished_; }
  /// The FSM (nullptr until the params are checked and the features resolved).
  const Skill* skill() const { return skill_.get(); }

  // SkillContext
  const Logger& log() const override { return log_; }
  const nlohmann::json& params() const override { return params_; }
  const std::map<std::string, ResolvedFeature>& features() const override { return features_; }
  const Devices& devices() const override { return devices_; }
  void progress(double fraction, const std::string& message) override;
  std::uint64_t after(std::chrono::nanoseconds delay, std::function<void()> handler) override;
  void cancel_timer(std::uint64_t id) override;

 private:
  void resolve_next();
  void start_skill();
  void finish(const SkillResult& result);

  const SkillType& type_;
  nlohmann::json raw_params_;
  nlohmann::json params_;
  Devices devices_;
  Timers& timers_;
  Logger log_;
  Callbacks callbacks_;
  Options options_;
  std::vector<std::string> to_resolve_;  // names of feature_ref params not yet resolved
  std::map<std::string, ResolvedFeature> features_;
  OpId resolving_ = 0;
  std::unique_ptr<Skill> skill_;
  bool finished_ = false;
  bool shutdown_requested_ = false;
  bool pause_requested_ = false;  // a PAUSE before the skill was made
};

}  // namespace rigger::skill_sdk
