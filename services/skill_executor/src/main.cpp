// skill_executor: hosts the built-in skills its configuration names. `skill_executor --describe
// [--config F]` prints the skill library those skills form (for offline recipe validation) and exits.
#include "builtin_skills.hpp"
#include "rigger/skill_sdk/executor.hpp"

int main(int argc, char** argv) {
  return rigger::skill_sdk::run_executor(
      argc, argv, {"skill_executor", "Hosts the skills its configuration names (--describe prints their library)."},
      rigger::skill_executor::builtin_skills());
}
