#include "collaborative_move_load.hpp"

#include "rigger/skill_sdk/states.hpp"
#include "rigger/skill_sdk/params.hpp"

namespace rigger::skill_executor {

const skill::SkillDescription& CollaborativeMoveLoadSkill::describe() {
  static const skill::SkillDescription kDescription = [] {
    skill::SkillDescription d;
    d.name = "CollaborativeMoveLoad";
    d.kind = skill::SkillKind::kSkill;
    d.description =
        "The operator guides the crane-carried load held by the robot with the joystick: admittance "
        "control of robot and crane (ROBOT_AND_CRANE, reference JOYSTICK) until the operator answers "
        "'done' (or duration_s passed); then admittance OFF, and the world model is told the object is no "
        "longer localized.";
    d.params = {
        params::object("object", "The crane-carried object the robot holds.", "load"),
        params::choice("reference", {"joystick"}).fallback("joystick").doc(
            "The motion reference: the operator's joystick (rigger/operator/joystick). Visual servoing is "
            "InsertVisuallyGuided's."),
        params::number("duration_s").unit("s").range(0.0, 3600.0).fallback(0.0).doc(
            "Ends with SUCCESS after this time (the operator may end earlier); 0: only the operator's 'done' ends it."),
        params::number("max_duration_s").unit("s").range(1.0, 7200.0).fallback(600.0).doc(
            "With duration_s = 0: fails with TIMEOUT when the operator did not answer within this time."),
        params::number("path_stiffness_n_per_m").unit("N/m").range(0.0, 2000.0).fallback(200.0).doc(
            "The robot law's spring (x, y, z) towards the joystick's path: what the load's pull on the robot (the "
            "crane lagging or leading) made the robot give way is taken back once the pull is inside the force "
            "deadband, so the load ends where the joystick put it. 0: free admittance, where that give-way stays (up "
            "to ~7 mm over a 20 cm jog in the simulated cell)."),
    };
    d.resources = {"robot", "crane", "operator", "$object"};
    d.preconditions = {*skill::parse_predicate("attached(robot,$object)")};
    d.postconditions = {*skill::parse_predicate("moved($object)"), *skill::parse_predicate("!localized($object)")};
    d.pausable = true;
    return d;
  }();
  return kDescription;
}

CollaborativeMoveLoadSkill::CollaborativeMoveLoadSkill() {
  const auto stop = [this](SafeStopDone done) { safe_stop(done); };
  add_state({"check_crane", [this] { check_crane(); }, nothing_to_stop});
  add_state({"crane_external", [this] { crane_external(); }, nothing_to_stop});
  // Paused, admittance goes OFF (robot and crane at rest, magnet on); resumed, it is engaged again.
  add_state({"engage", [this] { engage(); }, stop, stop, "engage"});
  add_state({"guide", [this] { guide(); }, stop, stop, "engage"});
  add_state({"disengage", [this] { disengage(); }, stop});
}

void CollaborativeMoveLoadSkill::safe_stop(const SafeStopDone& done) {
  admittance_safe_stop(ctx().devices().admittance, nullptr, {}, done);
}

void CollaborativeMoveLoadSkill::check_crane() {
  const Devices& devices = ctx().devices();
  if (!require_devices({{devices.admittance != nullptr, "an admittance controller"},
                        {devices.crane != nullptr, "a crane monitor"},
                        {devices.operator_panel != nullptr, "an operator panel"}}))
    return;
  ctx().progress(0.05, "checking the crane");
  check_crane_health([this] { transition("crane_external"); });
}

void CollaborativeMoveLoadSkill::crane_external() {
  request_crane_external([this] { transition("engage"); });
}

void CollaborativeMoveLoadSkill::engage() {
  ctx().progress(0.1, "admittance ROBOT_AND_CRANE with the joystick");
  AdmittanceRequest request;
  request.mode = AdmittanceModeRequest::kRobotAndCrane;
  request.reference = AdmittanceReference::kJoystick;
  const double k = params().at("path_stiffness_n_per_m").get<double>();
  request.stiffness = {k, k, k, 0.0, 0.0, 0.0};
  engage_admittance(request, "admittance ROBOT_AND_CRANE", [this] { transition("guide"); });
}

void CollaborativeMoveLoadSkill::guide() {
  const Devices& devices = ctx().devices();
  const std::string object = params().at("object").get<std::string>();
  const double duration_s = params().at("duration_s").get<double>();
  const double max_duration_s = params().at("max_duration_s").get<double>();
  ctx().progress(-1.0, "the operator guides " + object + " with the joystick; answer 'done' when it is in place");

  watch_crane_health();
  watch_admittance(AdmittanceModeRequest::kRobotAndCrane, AdmittanceReference::kJoystick);

  OperatorPanel* panel = devices.operator_panel;
  OperatorPromptSpec spec;
  spec.kind = "confirm";
  spec.title = "Guide the " + object;
  spec.text = "Guide the " + object +
              " with the joystick (robot and crane follow). Answer done when it is in place, "
              "abort to stop.";
  spec.options = {"done", "abort"};
  spec.details = {{"object", object}, {"duration_s", duration_s}};
  spec.timeout_s = duration_s > 0.0 ? duration_s : max_duration_s;
  const OpId prompt = panel->ask(spec, from_seconds(spec.timeout_s + 1.0), guard([this](std::optional<std::string> a) {
                                   if (a && *a == "done")
                                     transition("disengage");
                                   else if (a)
                                     fail("OPERATOR_ABORTED", "the operator aborted the guided move");
                                   // No answer: the duration timers below decide.
                                 }));
  track([panel, prompt] { panel->withdraw(prompt); });

  if (duration_s > 0.0) {
    after(from_seconds(duration_s), [this] { transition("disengage"); });
  } else {
    after(from_seconds(max_duration_s), [this, max_duration_s] {
      fail("TIMEOUT",
           "the operator did not answer 'done' within " + std::to_string(static_cast<int>(max_duration_s)) + " s");
    });
  }
}

void CollaborativeMoveLoadSkill::disengage() {
  ctx().progress(0.95, "admittance OFF");
  disengage_admittance([this] {
    succeed_unlocalizing(params().at("object").get<std::string>(),
                         "the operator moved the load; admittance OFF, robot and crane at rest");
  });
}

}  // namespace rigger::skill_executor
