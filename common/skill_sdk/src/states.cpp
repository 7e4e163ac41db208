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

void CraneSkill::watch_admittance(AdmittanceModeRequest mode, AdmittanceReference reference,
                                  std::function<void(const AdmittanceSnapshot&)> on_engaged,
                                  std::function<bool(const std::string&)> own_fault) {
  AdmittanceController* admittance = ctx().devices().admittance;
  const auto cancel_fault_timer = [this] {
    if (admittance_fault_timer_ != 0) ctx().cancel_timer(admittance_fault_timer_);
    admittance_fault_timer_ = 0;
  };
  const OpId id =
      admittance->watch(guard([this, mode, reference, on_engaged = std::move(on_engaged),
                               own_fault = std::move(own_fault), cancel_fault_timer](const AdmittanceSnapshot& s) {
        if (!s.fault || (own_fault && own_fault(s.fault_code))) {
          cancel_fault_timer();
        } else if (admittance_fault_timer_ == 0) {
          const std::string code = admittance_fault_code(s.fault_code);
          const std::string message = "admittance_control: " + s.fault_code + " " + s.fault_text;
          admittance_fault_timer_ =
              ctx().after(kAdmittanceFaultGrace, guard([this, code, message] {
                            admittance_fault_timer_ = 0;
                            fail(code, message + " (for " + std::to_string(kAdmittanceFaultGrace.count()) + " ms)");
                          }));
        }
        if (s.mode != mode || s.reference != reference) {
          if (s.fault) {  // the controller went OFF by itself on a latched fault (CRANE_FAULT, COMMANDER_LOST, ...)
            fail(admittance_fault_code(s.fault_code),
                 "admittance_control stopped with fault " + s.fault_code + " " + s.fault_text);
            return;
          }
          fail("ADMITTANCE_PREEMPTED", std::string("admittance_control left ") + admittance_mode_name(mode) + "/" +
                                           admittance_reference_name(reference) + " (another command?)");
          return;
        }
        if (on_engaged) on_engaged(s);
      }));
  track([admittance, id] { admittance->cancel(id); });
  track(cancel_fault_timer);
}

void CraneSkill::disengage_admittance(std::function<void()> then) {
  AdmittanceController* admittance = ctx().devices().admittance;
  AdmittanceRequest off;
  off.mode = AdmittanceModeRequest::kOff;
  const OpId id =
      admittance->command(off, kAdmittanceStopTimeout, guard([this, then = std::move(then)](const OpResult& r) {
                            if (r.ok)
                              then();
                            else
                              fail("ADMITTANCE_FAULT", "admittance OFF not confirmed: " + r.code + ": " + r.message);
                          }));
  track([admittance, id] { admittance->cancel(id); });
}

void admittance_safe_stop(AdmittanceController* admittance, VisionTracker* tracker,
                          const std::vector<std::string>& objects, const Skill::SafeStopDone& done) {
  if (tracker != nullptr)
    for (const std::string& object : objects) tracker->command(TrackerRequest::kStop, object);
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
