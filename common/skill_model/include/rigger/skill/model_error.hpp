#pragma once
/// The error record shared by everything that checks a document against the skill model.

#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

namespace rigger::skill {

/// One problem in a document: where it is (a JSON pointer, RFC 6901, "" for the whole document)
/// and a message that says what was expected.
struct ModelError {
  std::string pointer;
  std::string message;

  /// "pointer: message", or just the message when the pointer is empty.
  std::string to_string() const;
  friend bool operator==(const ModelError& a, const ModelError& b) {
    return a.pointer == b.pointer && a.message == b.message;
  }
};

/// Thrown at setup (loading a library file, building a description in code) when a document is
/// not a valid skill description or library. Carries every error found, not only the first.
class SkillModelError : public std::runtime_error {
 public:
  explicit SkillModelError(std::vector<ModelError> errors, const std::string& context = "");
  const std::vector<ModelError>& errors() const { return errors_; }

 private:
  std::vector<ModelError> errors_;
};

/// A parsed value or the list of every error that prevented it. Used where throwing is not
/// allowed (steady state: an executor announcement arriving over DDS).
template <typename T>
struct Parsed {
  std::optional<T> value;
  std::vector<ModelError> errors;
  bool ok() const { return value.has_value() && errors.empty(); }
};

}  // namespace rigger::skill
