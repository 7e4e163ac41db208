#include "skill_registry.hpp"

#include "rigger/skill_executor/library.hpp"

#include <stdexcept>

#include "skills/attach_robot_to_load.hpp"
#include "skills/collaborative_move_load.hpp"
#include "skills/insert_visually_guided.hpp"
#include "skills/localize.hpp"
#include "skills/move_to.hpp"
#include "skills/pick_place.hpp"
#include "skills/release.hpp"
#include "skills/screw.hpp"

namespace rigger::skill_executor {

void SkillRegistry::add(SkillType type) {
  const std::string name = type.description.name;
  if (!type.make) throw std::invalid_argument("skill " + name + ": no factory");
  if (types_.count(name)) throw std::invalid_argument("skill " + name + " registered twice");
  // The description must be one the controller's validator accepts: check it here, at start-up.
  const auto parsed = skill::parse_description(skill::to_json(type.description), "/skills/" + name);
  if (!parsed.ok()) {
    std::string text = "skill " + name + " has an invalid description:";
    for (const auto& e : parsed.errors) text += " " + e.pointer + ": " + e.message + ";";
    throw std::invalid_argument(text);
  }
  types_.emplace(name, std::move(type));
}

const SkillType* SkillRegistry::find(const std::string& name) const {
  auto it = types_.find(name);
  return it == types_.end() ? nullptr : &it->second;
}

std::vector<std::string> SkillRegistry::names() const {
  std::vector<std::string> out;
  for (const auto& [name, type] : types_) out.push_back(name);
  return out;
}

nlohmann::json SkillRegistry::library_json(const std::vector<std::string>& names) const {
  nlohmann::json skills = nlohmann::json::array();
  for (const auto& name : names) {
    const SkillType* type = find(name);
    if (!type) {
      std::string known;
      for (const auto& n : this->names()) known += (known.empty() ? "" : ", ") + n;
      throw std::invalid_argument("unknown skill '" + name + "'; this binary has: " + known);
    }
    skills.push_back(skill::to_json(type->description));
  }
  return {{"library_version", 1}, {"skills", skills}};
}

SkillRegistry builtin_skills() {
  SkillRegistry registry;
  registry.add({MoveToSkill::describe(), [] { return std::make_unique<MoveToSkill>(); }});
  registry.add({LocalizeSkill::describe(), [] { return std::make_unique<LocalizeSkill>(); }});
  registry.add({ScrewSkill::describe(), [] { return std::make_unique<ScrewSkill>(); }});
  registry.add({CollaborativeMoveLoadSkill::describe(), [] { return std::make_unique<CollaborativeMoveLoadSkill>(); }});
  registry.add({InsertVisuallyGuidedSkill::describe(), [] { return std::make_unique<InsertVisuallyGuidedSkill>(); }});
  registry.add({AttachRobotToLoadSkill::describe(), [] { return std::make_unique<AttachRobotToLoadSkill>(); }});
  registry.add({ReleaseSkill::describe(), [] { return std::make_unique<ReleaseSkill>(); }});
  registry.add({PickSkill::describe(), [] { return std::make_unique<PickSkill>(); }});
  registry.add({PlaceSkill::describe(), [] { return std::make_unique<PlaceSkill>(); }});
  return registry;
}

nlohmann::json builtin_skill_library_json() {
  const SkillRegistry registry = builtin_skills();
  return registry.library_json(registry.names());
}

}  // namespace rigger::skill_executor
