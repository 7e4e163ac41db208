#include "rigger/recipe/live_library.hpp"

#include "rigger/recipe/conditions.hpp"
#include "rigger/base/bounded_json.hpp"

namespace rigger::recipe {
namespace {

const skill::SkillLibrary& controller_conditions() {
  static const skill::SkillLibrary library = skill::SkillLibrary::from_json(controller_conditions_json());
  return library;
}

// An executor's library: a few hundred skills at most, each a small document.
constexpr rigger::JsonLimits kAnnouncementLimits{1024U * 1024U, 32};

}  // namespace

nlohmann::json parse_announced_library(std::string_view text, std::string* error) {
  auto parsed = rigger::parse_json_bounded(text, kAnnouncementLimits);
  if (!parsed.ok()) {
    if (error) *error = parsed.error->to_string();
    return nullptr;
  }
  return std::move(parsed.value);
}

skill::SkillLibrary live_library(const std::vector<AnnouncedLibrary>& announced, std::vector<std::string>* problems) {
  skill::SkillLibrary library;
  for (const auto& [id, document] : announced) {
    if (document == nullptr || document->is_null()) {
      if (problems) problems->push_back("executor library not JSON executor=" + id);
      continue;
    }
    auto parsed = skill::SkillLibrary::parse(*document);
    if (!parsed.value) {
      if (problems)
        problems->push_back("executor library invalid executor=" + id + " errors=" + std::to_string(parsed.errors.size()));
      continue;
    }
    for (const auto& e : library.merge(*parsed.value))
      if (problems) problems->push_back("executor library conflict executor=" + id + " at " + e.pointer + ": " + e.message);
  }
  for (const auto& [name, description] : controller_conditions().descriptions())
    if (library.find(name) == nullptr) library.add(description);
  return library;
}

}  // namespace rigger::recipe
