#pragma once
/// @file
/// Reusable states: the crane's health check, its external control and a watch of its health (CraneSkill,
/// for every skill that acts while the crane carries the load), and the pieces shared by the skills that
/// move that load with robot and crane under admittance control (CollaborativeMoveLoad,
/// InsertVisuallyGuided): engaging the admittance controller, watching it while engaged and
/// disengaging it, the collaborative safe stop and the classification of admittance faults.

#include <chrono>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "rigger/skill_sdk/cell_devices.hpp"
#include "rigger/skill_sdk/skill.hpp"

namespace rigger::skill_sdk {

/// How long admittance OFF (robot and crane ramped to zero) may take to be confirmed.
inline constexpr std::chrono::seconds kAdmittanceStopTimeout{5};
/// How long an admittance mode change may take to be confirmed.
inline constexpr std::chrono::seconds kAdmittanceEngageTimeout{2};
/// Crane state: the precondition wants a state this fresh; the watch fails after this much silence.
inline constexpr std::chrono::seconds kCraneStateMaxAge{1};
inline constexpr std::chrono::seconds kCraneCheckTimeout{2};
inline constexpr std::chrono::milliseconds kCraneMaxSilence{500};
inline constexpr std::chrono::seconds kCraneExternalTimeout{3};
/// An admittance fault must last this long to fail the skill: the controller's output is zero while it
/// reports a fault, so waiting is safe, and a momentary WRENCH_STALE (a late sensor sample on a loaded
/// host) does not end a long collaborative motion. Crane faults seen on rigger/crane/state fail at once.
inline constexpr std::chrono::milliseconds kAdmittanceFaultGrace{500};

/// A skill that acts while the crane carries the load. Each method is the action of one of the skill's
/// states: it starts the crane operation as an operation of the current state (cancelled when the state is
/// left) and ends by calling `then`, or by failing the skill with kCraneFault.
class CraneSkill : public Skill {
 protected:
  /// The crane's state fresher than `max_age` and showing no problem → `then`. Fails DEVICE_UNAVAILABLE
  /// when the executor has no crane monitor.
  void check_crane_health(std::function<void()> then, std::chrono::nanoseconds max_age = kCraneStateMaxAge,
                          std::chrono::nanoseconds timeout = kCraneCheckTimeout);
  /// External control granted (the admittance law commands the crane's velocity) → `then`.
  void request_crane_external(std::function<void()> then, std::chrono::nanoseconds timeout = kCraneExternalTimeout);
  /// For as long as the current state lasts: a crane state showing a problem, or none for `max_silence`,
  /// fails the skill. Does nothing when the executor has no crane monitor.
  void watch_crane_health(std::chrono::nanoseconds max_silence = kCraneMaxSilence);
  /// The admittance controller switched to `request` → `then`; a refusal fails the skill with
  /// ADMITTANCE_PREEMPTED (another client took it) or ADMITTANCE_FAULT, saying "engaging `what`".
  void engage_admittance(const AdmittanceRequest& request, const std::string& what, std::function<void()> then);
  /// For as long as the current state lasts, watches the admittance controller engaged in `mode` with
  /// `reference`: a fault that lasts kAdmittanceFaultGrace fails the skill with admittance_fault_code();
  /// a state in another mode or reference fails it at once (with admittance_fault_code() when the
  /// controller went OFF on a latched fault, else ADMITTANCE_PREEMPTED). Every state still in `mode` and
  /// `reference` goes to `on_engaged`. A fault whose code satisfies `own_fault` gets no grace timer: the
  /// skill judges it in `on_engaged` (e.g. the visual servo's stops for lack of tracking).
  void watch_admittance(AdmittanceModeRequest mode, AdmittanceReference reference,
                        std::function<void(const AdmittanceSnapshot&)> on_engaged = nullptr,
                        std::function<bool(const std::string&)> own_fault = nullptr);
  /// Admittance OFF confirmed (robot and crane at rest; the magnet is not touched) → `then`; else fails
  /// ADMITTANCE_FAULT ("admittance OFF not confirmed: …") after kAdmittanceStopTimeout at the latest.
  void disengage_admittance(std::function<void()> then);

 private:
  std::uint64_t admittance_fault_timer_ = 0;  ///< a fault is being reported (see kAdmittanceFaultGrace)
};

/// The collaborative safe stop: admittance OFF (robot twist and crane velocity ramp to zero; the
/// magnet is not touched and stays on), done(true) once the admittance state reports OFF with both
/// outputs at rest; done(false) when it does not within kAdmittanceStopTimeout. When `tracker` is
/// given, the tracker's continuous mode is stopped too (TRACK_STOP for each of `objects`).
void admittance_safe_stop(AdmittanceController* admittance, VisionTracker* tracker,
                          const std::vector<std::string>& objects, const Skill::SafeStopDone& done);

/// True for the admittance fault codes that mean the crane side failed ("CRANE_FAULT" and the crane
/// law's own "FORCE_*" faults are not: they are the admittance controller's).
bool is_crane_fault_code(const std::string& code);
/// The skill's failure code for an admittance fault code: kCraneFault for crane-side codes, else
/// "ADMITTANCE_FAULT".
std::string admittance_fault_code(const std::string& code);
/// True for the codes that mean the visual servo stopped its reference for lack of tracking
/// (TRACKING_LOST, LOAD_/TARGET_QUALITY_LOW, LOAD_/TARGET_POSE_STALE, LOAD_/TARGET_POSE_INVALID).
bool is_tracking_stop_code(const std::string& code);

/// "12.3 mm, 0.80 deg" for a servo error.
std::string servo_error_text(double error_m, double error_rad);

}  // namespace rigger::skill_sdk
