#pragma once
/// @file
/// Skill types by name: each with its description (what the executor announces and
/// `skill_executor --describe` prints) and a factory. An executor's configuration names the skills it
/// hosts, so one binary runs as robot-skills, perception-skills or operator-skills executor.

#include <functional>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "rigger/skill/skill_description.hpp"
#include "rigger/skill_sdk/skill.hpp"

namespace rigger::skill_sdk {

struct SkillType {
  skill::SkillDescription description;
  std::function<std::unique_ptr<Skill>()> make;
};

class SkillRegistry {
 public:
  /// @throws std::invalid_argument on a duplicate name, a missing factory or a description that
  /// rigger::skill::parse_description refuses (the message lists every error).
  void add(SkillType type);
  /// Adds skill `S`: its description from `S::describe()`, made by `S`'s default constructor.
  template <typename S>
  void add() {
    add({S::describe(), [] { return std::make_unique<S>(); }});
  }
  /// nullptr for an unknown name.
  const SkillType* find(const std::string& name) const;
  /// Every registered name, sorted.
  std::vector<std::string> names() const;
  /// `{ "library_version": 1, "skills": [description…] }` for `names` (in that order).
  /// @throws std::invalid_argument naming an unknown skill.
  nlohmann::json library_json(const std::vector<std::string>& names) const;

 private:
  std::map<std::string, SkillType> types_;
};

}  // namespace rigger::skill_sdk
