#pragma once
/// A set of skill, monitor and condition descriptions, and the library file
/// `{ "library_version": 1, "skills": [ … ] }` that `skill_executor --describe` exports and that
/// offline validation (`riggerctl validate`) reads.

#include <cstddef>
#include <filesystem>
#include <map>
#include <string>
#include <string_view>
#include <vector>

#include <nlohmann/json.hpp>

#include "rigger/base/bounded_json.hpp"
#include "rigger/skill/model_error.hpp"
#include "rigger/skill/skill_description.hpp"

namespace rigger::skill {

/// Version of the library file format this code reads and writes.
inline constexpr int kLibraryVersion = 1;

/// A set of descriptions with unique names (across kinds). Value type; not synchronized.
class SkillLibrary {
 public:
  SkillLibrary() = default;

  /// Adds a description. Returns false (and changes nothing) when a description with the same
  /// name is present and differs; adding an identical one again is a no-op returning true.
  bool add(SkillDescription description);

  /// Adds every description of `other`; returns one error per conflicting name (those are not added).
  std::vector<ModelError> merge(const SkillLibrary& other);

  /// The description named `name`, or nullptr.
  const SkillDescription* find(std::string_view name) const;

  /// Names of the descriptions of one kind, sorted.
  std::vector<std::string> names(SkillKind kind) const;

  std::size_t size() const { return descriptions_.size(); }
  bool empty() const { return descriptions_.empty(); }

  /// Every description, ordered by name.
  const std::map<std::string, SkillDescription, std::less<>>& descriptions() const { return descriptions_; }

  /// {"library_version": 1, "skills": [...]}, skills ordered by name.
  nlohmann::json to_json() const;

  /// Parses a library document without throwing; every error has its JSON pointer.
  static Parsed<SkillLibrary> parse(const nlohmann::json& json);

  /// Throwing form of parse() for setup code (SkillModelError with every error).
  static SkillLibrary from_json(const nlohmann::json& json);

  /// Reads a library file with a bounded parser. Throws SkillModelError naming the file, the
  /// position or JSON pointer, and what was expected.
  static SkillLibrary load_file(const std::filesystem::path& path, const JsonLimits& limits = {});

  /// Writes the library file (pretty-printed, trailing newline). Throws std::runtime_error when
  /// the file cannot be written.
  void save_file(const std::filesystem::path& path) const;

 private:
  std::map<std::string, SkillDescription, std::less<>> descriptions_;
};

}  // namespace rigger::skill
