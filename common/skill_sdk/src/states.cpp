#include "rigger/skill_sdk/states.hpp"

#include <cmath>
#include <cstdio>

namespace rigger::skill_sdk {

void CraneSkill::check_crane_health(std::function<void()> then, std::chrono::nanoseconds max_age,
                                    std::chrono::nanoseconds timeout) {
  CraneMonitor* crane = ctx().devices().crane;
  if (crane == nullptr) {
    fail("DEVICE_UNAVAILABLE", "this executor has no crane monitor");
    return;
  }
  const OpId id = crane->check_health(max_age, timeout, guard([this, then = std::move(then)](const OpResult& r) {
                                        if (r.ok)
                                          then();
                                        else
                                          fail(kCraneFault, r.message);
                                      }));
  track([crane, id] { crane->cancel(id); });
}

void CraneSkill::request_crane_external(std::function<void()> then, std::chrono::nanoseconds timeout) {
  CraneMonitor* crane = ctx().devices().crane;
  if (crane == nullptr) {
    fail("DEVICE_UNAVAILABLE", "this executor has no crane monitor");
    return;
  }
  const OpId id = crane->request_external(timeout, guard([this, then = std::move(then)](const OpResult& r) {
                                            if (r.ok)
                                              then();
                                            else
                                              fail(kCraneFault, r.message);
                                          }));
  track([crane, id] { crane->cancel(id); });
}

void CraneSkill::watch_crane_health(std::chrono::nanoseconds max_silence) {
  CraneMonitor* crane = ctx().devices().crane;
  if (crane == nullptr) return;
  const OpId id = crane->watch_health(max_silence, guard([this](const OpResult& problem) {
                                        fail(kCraneFault, "the crane reported a problem in state " + state() + ": " +
                                                              problem.message);
                                      }));
  track([crane, id] { crane->cancel(id); });
}

void CraneSkill::engage_admittance(const AdmittanceRequest& request, const std::string& what,
                                   std::function<void()> then) {
  AdmittanceController* admittance = ctx().devices().admittance;
  const OpId id = admittance->command(request, kAdmittanceEngageTimeout,
                                      guard([this, what, then = std::move(then)](const OpResult& r) {
                                        if (r.ok) {
                                          then();
                                          return;
                                        }
                                        fail(r.code == "ADMITTANCE_PREEMPTED" ? r.code : "ADMITTANCE_FAULT",
                                             "engaging " + what + ": " + r.code + ": " + r.message);
                                      }));
  track([admittance, id] { admittance->cancel(id); });
}

void admittance_safe_stop(AdmittanceController* admittance, VisionTracker* tracker, const std::string& object,
                          const Skill::SafeStopDone& done) {
  if (tracker != nullptr) tracker->command(TrackerRequest::kStop, object);
  if (admittance == nullptr) {
    done(true, "no admittance controller: nothing was commanded");
    return;
  }
  AdmittanceRequest off;
  off.mode = AdmittanceModeRequest::kOff;
  admittance->command(off, kAdmittanceStopTimeout, [done](const OpResult& result) {
    done(result.ok,
         result.ok ? "admittance OFF, robot and crane at rest, magnet on" : result.code + ": " + result.message);
  });
}

bool is_crane_fault_code(const std::string& code) {
  return code == "CRANE_FAULT" || code == "CRANE_LINK_DOWN";
}

std::string admittance_fault_code(const std::string& code) {
  return is_crane_fault_code(code) ? kCraneFault : "ADMITTANCE_FAULT";
}

bool is_tracking_stop_code(const std::string& code) {
  return code == "TRACKING_LOST" || code == "LOAD_QUALITY_LOW" || code == "TARGET_QUALITY_LOW" ||
         code == "LOAD_POSE_STALE" || code == "TARGET_POSE_STALE" || code == "LOAD_POSE_INVALID" ||
         code == "TARGET_POSE_INVALID";
}

std::string servo_error_text(double error_m, double error_rad) {
  char buf[96];
  std::snprintf(buf, sizeof buf, "%.1f mm, %.2f deg", error_m * 1000.0, error_rad * 180.0 / M_PI);
  return buf;
}

}  // namespace rigger::skill_sdk
