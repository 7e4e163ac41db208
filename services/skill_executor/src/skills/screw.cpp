#include "screw.hpp"

#include "fixed_text.hpp"
#include "rigger/skill_sdk/primitives.hpp"
#include "rigger/skill_sdk/params.hpp"

namespace rigger::skill_executor {

std::string find_screw_hole(const nlohmann::json& features, const std::string& id, ScrewHole& hole) {
  const auto holes = features.find("screw_holes");
  if (holes == features.end() || !holes->is_array()) return "'" + hole.entity + "' has no screw holes";
  for (const auto& h : *holes) {
    if (!h.is_object() || h.value("id", std::string()) != id) continue;
    if (h.contains("screw_type") && h["screw_type"].is_string()) hole.screw_type = h["screw_type"].get<std::string>();
    if (h.contains("torque_nm") && h["torque_nm"].is_number()) hole.torque_nm = h["torque_nm"].get<double>();
    return "";
  }
  return "'" + hole.entity + "' has no screw hole '" + id + "'";
}

std::string per_hole_problem(const nlohmann::json& params, std::size_t holes) {
  for (const char* name : {"torque_per_hole_nm", "screw_type_per_hole"}) {
    const nlohmann::json& values = params.at(name);
    if (!values.empty() && values.size() != holes)
      return std::string("/params/") + name + ": expected " + std::to_string(holes) +
             " values, one per entry of /params/holes (or none), got " + std::to_string(values.size());
  }
  const nlohmann::json& types = params.at("screw_type_per_hole");
  for (std::size_t i = 0; i < types.size(); ++i) {
    if (types[i].get<std::string>().size() > 64)
      return "/params/screw_type_per_hole/" + std::to_string(i) + ": expected at most 64 bytes, got " +
             std::to_string(types[i].get<std::string>().size());
  }
  return "";
}

const skill::SkillDescription& ScrewSkill::describe() {
  static const skill::SkillDescription kDescription = [] {
    skill::SkillDescription d;
    d.name = "Screw";
    d.kind = skill::SkillKind::kSkill;
    d.description =
        "Prompts the operator hole by hole with the screw type, torque and position (rigger/operator/prompt) "
        "and waits for each confirmation (rigger/operator/response): done, failed or abort.";
    d.params = {
        params::string_list("holes").range(1.0, 32.0).doc(
            "Feature refs of the screw holes, in order, e.g. [\"target/h1\", \"target/h2\"]."),
        params::number("torque_nm").unit("Nm").range(0.0, 400.0).fallback(0.0).doc(
            "Tightening torque for every hole; 0: each hole's torque from the world model."),
        params::text("screw_type").at_most(64.0).fallback("").doc(
            "Screw type for every hole; empty: each hole's type from the world model."),
        params::number_list("torque_per_hole_nm").unit("Nm").range(0.0, 400.0).fallback(nlohmann::json::array()).doc(
            "Tightening torque hole by hole, one per entry of holes (or none); 0 for a hole: torque_nm, else "
            "the world model's."),
        params::string_list("screw_type_per_hole").range(0.0, 32.0).fallback(nlohmann::json::array()).doc(
            "Screw type hole by hole (each at most 64 bytes), one per entry of holes (or none); \"\" for "
            "a hole: screw_type, else the world model's."),
        params::number("timeout_per_hole_s").unit("s").range(1.0, 3600.0).fallback(600.0).doc(
            "Fails with OPERATOR_TIMEOUT when a hole is not confirmed within this time."),
        params::object("object", "The object being fastened (for the conditions).", "load"),
        params::object("target", "The object it is fastened to (for the conditions).", "target"),
    };
    d.resources = {"operator"};
    d.preconditions = {*skill::parse_predicate("inserted($object,$target)")};
    d.postconditions = {*skill::parse_predicate("fastened($object,$target)")};
    return d;
  }();
  return kDescription;
}

ScrewSkill::ScrewSkill() {
  add_state({"lookup", [this] { lookup(); }, nothing_to_stop});
  // The prompt is withdrawn when the state is left (tracked), before any safe stop runs.
  add_state({"prompt", [this] { prompt(); }, [](SafeStopDone done) { done(true, "prompt withdrawn"); }});
}

void ScrewSkill::lookup() {
  const Devices& devices = ctx().devices();
  if (devices.operator_panel == nullptr || devices.world_access == nullptr || devices.world == nullptr) {
    fail("DEVICE_UNAVAILABLE", devices.operator_panel == nullptr ? "this executor has no operator panel"
                                                                 : "this executor has no world model");
    return;
  }
  for (const auto& ref_json : params().at("holes")) {
    const std::string ref = ref_json.get<std::string>();
    const auto parts = split_feature_ref(ref);
    if (!parts) {
      fail("BAD_PARAMS", "/params/holes: \"" + ref + "\" is not a feature ref entity/hole (e.g. \"target/h1\")");
      return;
    }
    holes_.push_back(ScrewHole{ref, parts->first, parts->second, "", 0.0, Eigen::Vector3d::Zero()});
  }
  if (const std::string error = per_hole_problem(params(), holes_.size()); !error.empty()) {
    fail("BAD_PARAMS", error);
    return;
  }
  ctx().progress(0.0, "looking up " + std::to_string(holes_.size()) + " screw holes");
  lookup_next();
}

void ScrewSkill::lookup_next() {
  if (lookup_index_ == holes_.size()) {
    current_ = 0;
    transition("prompt");
    return;
  }
  ScrewHole& hole = holes_[lookup_index_];
  if (!features_.contains(hole.entity)) {  // one FEATURES query per entity
    WorldAccess* world = ctx().devices().world_access;
    const std::string entity = hole.entity;
    const OpId id = world->features(entity, kWorldTimeout,
                                    guard([this, entity](const OpResult& result, const nlohmann::json& features) {
                                      if (!result.ok) {
                                        fail(result.code, "features of '" + entity + "': " + result.message);
                                        return;
                                      }
                                      features_[entity] = features;
                                      lookup_next();
                                    }));
    track([world, id] { world->cancel(id); });
    return;
  }
  if (auto error = find_screw_hole(features_[hole.entity], hole.id, hole); !error.empty()) {
    fail("UNKNOWN_FEATURE", hole.ref + ": " + error);
    return;
  }
  // The hole's own value, else the one for every hole, else the world model's.
  const nlohmann::json& types = params().at("screw_type_per_hole");
  const nlohmann::json& torques = params().at("torque_per_hole_nm");
  std::string type_override = params().at("screw_type").get<std::string>();
  double torque_override = params().at("torque_nm").get<double>();
  if (!types.empty() && !types[lookup_index_].get<std::string>().empty())
    type_override = types[lookup_index_].get<std::string>();
  if (!torques.empty() && torques[lookup_index_].get<double>() > 0.0) torque_override = torques[lookup_index_].get<double>();
  if (!type_override.empty()) hole.screw_type = type_override;
  if (torque_override > 0.0) hole.torque_nm = torque_override;
  if (hole.screw_type.empty() || !(hole.torque_nm > 0.0)) {
    fail("BAD_PARAMS", hole.ref + ": the world model gives no screw type or torque and the params give none");
    return;
  }
  FeatureResolver* resolver = ctx().devices().world;
  const OpId id = resolver->resolve(
      hole.ref, "world", kWorldTimeout, guard([this](const OpResult& result, const ResolvedFeature& feature) {
        ScrewHole& h = holes_[lookup_index_];
        if (!result.ok) {
          fail(result.code.empty() ? "UNKNOWN_FEATURE" : result.code, "position of " + h.ref + ": " + result.message);
          return;
        }
        h.position_world_m = feature.pose.translation();
        ++lookup_index_;
        lookup_next();
      }));
  track([resolver, id] { resolver->cancel(id); });
}

void ScrewSkill::prompt() {
  const ScrewHole& hole = holes_[current_];
  const std::string of = std::to_string(current_ + 1) + "/" + std::to_string(holes_.size());
  const double timeout_s = params().at("timeout_per_hole_s").get<double>();
  OperatorPromptSpec spec;
  spec.kind = "screw";
  spec.title = "Screw hole " + hole.id + " (" + of + ")";
  spec.text = "Screw a " + hole.screw_type + " into " + hole.ref + " and tighten it to " + fixed(hole.torque_nm, 1) +
              " Nm; answer done, failed or abort.";
  spec.options = {kDone, kFailed, kAbort};
  spec.details = {{"hole", hole.id},
                  {"hole_ref", hole.ref},
                  {"screw_type", hole.screw_type},
                  {"torque_nm", hole.torque_nm},
                  {"position_m", {hole.position_world_m.x(), hole.position_world_m.y(), hole.position_world_m.z()}}};
  spec.timeout_s = timeout_s;
  ctx().progress(static_cast<double>(current_) / static_cast<double>(holes_.size()),
                 "hole " + hole.ref + " (" + of + "): " + hole.screw_type + " at " + fixed(hole.torque_nm, 1) + " Nm");
  OperatorPanel* panel = ctx().devices().operator_panel;
  const OpId id =
      panel->ask(spec, from_seconds(timeout_s), guard([this, timeout_s](std::optional<std::string> answer) {
                   const ScrewHole& h = holes_[current_];
                   if (!answer) {
                     fail("OPERATOR_TIMEOUT", "hole " + h.ref + " not confirmed within " + fixed(timeout_s, 0) + " s");
                   } else if (*answer == kDone) {
                     ++current_;
                     if (current_ == holes_.size()) {
                       ctx().progress(1.0, "all " + std::to_string(holes_.size()) + " holes screwed");
                       succeed("the operator screwed " + std::to_string(holes_.size()) + " holes");
                     } else {
                       transition("prompt");  // the next hole (this prompt is withdrawn first)
                     }
                   } else if (*answer == kFailed) {
                     fail("SCREW_FAILED", "the operator reports hole " + h.ref + " failed");
                   } else {
                     fail("OPERATOR_ABORTED", "the operator aborted at hole " + h.ref);
                   }
                 }));
  track([panel, id] { panel->withdraw(id); });
}

}  // namespace rigger::skill_executor
