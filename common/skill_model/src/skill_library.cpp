#include "rigger/skill/skill_library.hpp"

#include <fstream>
#include <set>
#include <stdexcept>
#include <utility>

#include "skill_json_util.hpp"

namespace rigger::skill {

bool SkillLibrary::add(SkillDescription description) {
  const auto it = descriptions_.find(description.name);
  if (it != descriptions_.end()) {
    return it->second == description;
  }
  std::string name = description.name;
  descriptions_.emplace(std::move(name), std::move(description));
  return true;
}

std::vector<ModelError> SkillLibrary::merge(const SkillLibrary& other) {
  std::vector<ModelError> errors;
  for (const auto& [name, description] : other.descriptions_) {
    if (!add(description)) {
      errors.push_back({"", "conflicting descriptions of \"" + name +
                                "\": two sources describe it differently; expected identical descriptions"});
    }
  }
  return errors;
}

const SkillDescription* SkillLibrary::find(std::string_view name) const {
  const auto it = descriptions_.find(name);
  return it == descriptions_.end() ? nullptr : &it->second;
}

std::vector<std::string> SkillLibrary::names(SkillKind kind) const {
  std::vector<std::string> out;
  for (const auto& [name, description] : descriptions_) {
    if (description.kind == kind) {
      out.push_back(name);
    }
  }
  return out;
}

nlohmann::json SkillLibrary::to_json() const {
  nlohmann::json skills = nlohmann::json::array();
  for (const auto& entry : descriptions_) {
    skills.push_back(skill::to_json(entry.second));
  }
  return {{"library_version", kLibraryVersion}, {"skills", std::move(skills)}};
}

Parsed<SkillLibrary> SkillLibrary::parse(const nlohmann::json& json) {
  Parsed<SkillLibrary> result;
  auto& errors = result.errors;
  if (!json.is_object()) {
    errors.push_back({"", "expected a library object {\"library_version\": 1, \"skills\": [...]}, got " +
                              detail::describe_json(json)});
    return result;
  }
  detail::check_keys(json, "", {"library_version", "skills", "description"}, errors);
  if (!json.contains("library_version")) {
    errors.push_back({"", "missing \"library_version\": expected " + std::to_string(kLibraryVersion)});
  } else if (json["library_version"] != kLibraryVersion) {
    errors.push_back({"/library_version", "unsupported library version: expected " + std::to_string(kLibraryVersion) +
                                              ", got " + json["library_version"].dump()});
  }
  SkillLibrary library;
  if (!json.contains("skills") || !json["skills"].is_array()) {
    errors.push_back({json.contains("skills") ? "/skills" : "",
                      "expected \"skills\": an array of skill, monitor and condition descriptions"});
  } else {
    const auto& skills = json["skills"];
    for (std::size_t i = 0; i < skills.size(); ++i) {
      const std::string pointer = "/skills/" + std::to_string(i);
      auto parsed = parse_description(skills[i], pointer);
      errors.insert(errors.end(), parsed.errors.begin(), parsed.errors.end());
      if (!parsed.value) {
        continue;
      }
      if (library.find(parsed.value->name) != nullptr) {
        errors.push_back({pointer + "/name", "duplicate name \"" + parsed.value->name +
                                                 "\": names are unique across skills, monitors and conditions"});
        continue;
      }
      library.add(std::move(*parsed.value));
    }
  }
  if (errors.empty()) {
    result.value = std::move(library);
  }
  return result;
}

SkillLibrary SkillLibrary::from_json(const nlohmann::json& json) {
  auto parsed = parse(json);
  if (!parsed.ok()) {
    throw SkillModelError(std::move(parsed.errors), "invalid skill library");
  }
  return std::move(*parsed.value);
}

SkillLibrary SkillLibrary::load_file(const std::filesystem::path& path, const JsonLimits& limits) {
  auto text = parse_json_file_bounded(path, limits);
  if (!text.ok()) {
    throw SkillModelError({{"", text.error->to_string()}}, "cannot load skill library");
  }
  auto parsed = parse(text.value);
  if (!parsed.ok()) {
    throw SkillModelError(std::move(parsed.errors), "invalid skill library " + path.string());
  }
  return std::move(*parsed.value);
}

void SkillLibrary::save_file(const std::filesystem::path& path) const {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  if (!out) {
    throw std::runtime_error("cannot write skill library " + path.string());
  }
  out << to_json().dump(2) << "\n";
  if (!out) {
    throw std::runtime_error("error while writing skill library " + path.string());
  }
}

}  // namespace rigger::skill
