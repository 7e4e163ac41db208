#pragma once
/// @file
/// CollaborativeMoveLoad: the operator guides the crane-carried load, held by the robot, with the
/// joystick; robot and crane follow under admittance control.
///
///   check_crane ─healthy─▶ crane_external ─granted─▶ engage ─ROBOT_AND_CRANE─▶ guide ─done / duration─▶ disengage
///   ─OFF─▶ SUCCESS
///
/// check_crane: a fresh rigger/crane/state shows link, ready, no fault, e-stop or overload (precondition).
/// crane_external: CRANE_REQUEST_EXTERNAL until enabled and external control granted.
/// engage: rigger/admittance/command mode ROBOT_AND_CRANE, reference JOYSTICK, source = executor id;
/// confirmed by rigger/admittance/state.
/// guide: a prompt (kind "confirm", options ["done","abort"]) asks the operator to answer "done" when
/// the load is in place; ends on "done", or after duration_s when it is > 0. Watches the crane (fault,
/// link, silence → CRANE_FAULT) and the admittance state (a fault lasting kAdmittanceFaultGrace →
/// ADMITTANCE_FAULT, or CRANE_FAULT for a crane-side fault; another mode commanded by someone else →
/// ADMITTANCE_PREEMPTED).
/// disengage: admittance OFF, confirmed with robot and crane outputs at rest.
///
/// Safe stops: check_crane, crane_external → nothing commanded (the crane's setpoints stay zero);
/// engage, guide, disengage → admittance OFF and wait for the state to report it with both outputs at
/// rest (the magnet stays on); the prompt is withdrawn when guide is left.
/// Params: object (default "load"), reference (enum, only "joystick"), duration_s (0–3600 s, default 0: until the
/// operator answers), max_duration_s (1–7200 s, default 600). Claims robot, crane, operator, $object. Pre:
/// attached(robot,$object). Post: moved($object), !localized($object) (its pose changed). Failure codes:
/// DEVICE_UNAVAILABLE, CRANE_FAULT, ADMITTANCE_FAULT, ADMITTANCE_PREEMPTED, OPERATOR_ABORTED, TIMEOUT (no "done" within
/// max_duration_s).

#include "rigger/skill_sdk/cell_devices.hpp"
#include "rigger/skill_sdk/skill.hpp"
#include "sdk.hpp"

namespace rigger::skill_executor {

class CollaborativeMoveLoadSkill final : public CraneSkill {
 public:
  static const skill::SkillDescription& describe();
  CollaborativeMoveLoadSkill();

 private:
  void check_crane();
  void crane_external();
  void engage();
  void guide();
  void disengage();
  void safe_stop(const SafeStopDone& done);
};

}  // namespace rigger::skill_executor
