#include "rigger/skill/model_error.hpp"

namespace rigger::skill {
namespace {

std::string summarize(const std::vector<ModelError>& errors, const std::string& context) {
  std::string out = context.empty() ? "invalid skill model document" : context;
  out += " (" + std::to_string(errors.size()) + (errors.size() == 1 ? " error)" : " errors)");
  for (const auto& e : errors) {
    out += "\n  " + e.to_string();
  }
  return out;
}

}  // namespace

std::string ModelError::to_string() const { return pointer.empty() ? message : pointer + ": " + message; }

SkillModelError::SkillModelError(std::vector<ModelError> errors, const std::string& context)
    : std::runtime_error(summarize(errors, context)), errors_(std::move(errors)) {}

}  // namespace rigger::skill
