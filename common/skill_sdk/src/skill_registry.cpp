#include "rigger/skill_sdk/skill_registry.hpp"

#include <stdexcept>

namespace rigger::skill_sdk {

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

}  // namespace rigger::skill_sdk
