#pragma once
/// @file
/// Recipe admission: whether a recipe that arrived on rigger/task/recipe runs, waits for an executor, or
/// is rejected and why. Pure logic (no DDS, no journal): the node asks, then journals and starts what
/// is admitted. The decision is typed (Admission::Outcome, RejectCode), never read back from message
/// text: the validator gives each error its kind (recipe::ErrorCode).

#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "rigger/recipe/recipe_validator.hpp"

namespace rigger::task_controller {

/// Why a recipe is rejected; to_string() is the TaskStatus code on the wire.
enum class RejectCode {
  kInvalidRecipe,     ///< INVALID_RECIPE: fails validation, or the sample's task_id is empty or differs
  kDuplicateTask,     ///< DUPLICATE_TASK: the task id is running, waiting or in the journal
  kResourceConflict,  ///< RESOURCE_CONFLICT: a resource it claims is claimed by a running task
  kJournalError,      ///< JOURNAL_ERROR: the journal could not record it (decided by the node)
};
const char* to_string(RejectCode code);

/// A running task's claim on resources (sorted, as ValidatedRecipe::resources).
struct ResourceClaim {
  std::string task_id;
  const std::vector<std::string>* resources = nullptr;
};

struct AdmissionRequest {
  std::string task_id;    ///< the Recipe sample's task_id
  std::string_view text;  ///< its recipe_json
  bool id_used = false;   ///< the id names a running or waiting task, or one in the journal
  /// Hold a recipe whose only errors are unknown skills or monitors: their executor may not have
  /// announced itself yet (executor_wait_s). False on the retry after the wait ran out.
  bool may_wait = false;
  std::vector<ResourceClaim> running;  ///< unfinished tasks, in the order conflicts are looked for
};

struct Admission {
  enum class Outcome { kAdmitted, kWait, kRejected };
  Outcome outcome = Outcome::kRejected;
  RejectCode code = RejectCode::kInvalidRecipe;  ///< when rejected
  std::string message;                           ///< rejected: why; kWait: the first unknown name
  std::vector<recipe::Error> errors;             ///< rejected: every validation error
  std::vector<recipe::ErrorCode> error_codes;    ///< the kind of each of `errors`
  std::optional<recipe::ValidatedRecipe> recipe;  ///< admitted
};

/// Decides on one recipe; validation runs against `validator`'s library. Never throws on bad input.
Admission admit(const AdmissionRequest& request, const recipe::RecipeValidator& validator);

}  // namespace rigger::task_controller
