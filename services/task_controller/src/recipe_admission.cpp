#include "recipe_admission.hpp"

#include <algorithm>

namespace rigger::task_controller {
namespace {

Admission reject(RejectCode code, std::string message, std::vector<recipe::Error> errors = {}) {
  Admission a;
  a.outcome = Admission::Outcome::kRejected;
  a.code = code;
  a.message = std::move(message);
  a.errors = std::move(errors);
  return a;
}

/// The first element of sorted `a` also in sorted `b`.
const std::string* first_common(const std::vector<std::string>& a, const std::vector<std::string>& b) {
  for (const auto& x : a)
    if (std::binary_search(b.begin(), b.end(), x)) return &x;
  return nullptr;
}

}  // namespace

const char* to_string(RejectCode code) {
  switch (code) {
    case RejectCode::kInvalidRecipe: return "INVALID_RECIPE";
    case RejectCode::kDuplicateTask: return "DUPLICATE_TASK";
    case RejectCode::kResourceConflict: return "RESOURCE_CONFLICT";
    case RejectCode::kJournalError: return "JOURNAL_ERROR";
  }
  return "INVALID_RECIPE";
}

Admission admit(const AdmissionRequest& request, const recipe::RecipeValidator& validator) {
  const std::string& task_id = request.task_id;
  if (task_id.empty()) return reject(RejectCode::kInvalidRecipe, "the Recipe sample has an empty task_id");
  if (request.id_used)
    return reject(RejectCode::kDuplicateTask, "task id " + task_id + " was already used; submit under a new id");
  auto result = validator.validate_text(request.text);
  if (!result.ok()) {
    if (request.may_wait && recipe::only_unknown_leaves(result)) {
      Admission a;
      a.outcome = Admission::Outcome::kWait;
      a.message = result.errors.front().message;
      return a;
    }
    const std::string message = std::to_string(result.errors.size()) + " error(s); first: " +
                                result.errors.front().pointer + ": " + result.errors.front().message;
    Admission a = reject(RejectCode::kInvalidRecipe, message, std::move(result.errors));
    a.error_codes = std::move(result.codes);
    return a;
  }
  if (result.recipe->task_id != task_id)
    return reject(RejectCode::kInvalidRecipe, "task_id differs from the Recipe sample's",
                  {{"/task_id", "expected \"" + task_id + "\" (the Recipe sample's task_id), got \"" +
                                    result.recipe->task_id + "\""}});
  for (const auto& claim : request.running) {
    if (claim.resources == nullptr) continue;
    if (const std::string* common = first_common(result.recipe->resources, *claim.resources))
      return reject(RejectCode::kResourceConflict, "resource " + *common + " is claimed by running task " +
                                                        claim.task_id + "; wait for it or cancel it");
  }
  Admission a;
  a.outcome = Admission::Outcome::kAdmitted;
  a.recipe = std::move(result.recipe);
  return a;
}

}  // namespace rigger::task_controller
