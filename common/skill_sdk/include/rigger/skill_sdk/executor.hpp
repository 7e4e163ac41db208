#pragma once
/// @file
/// A skill executor process: the program an integrator's `main` hands its skills to.
///
///   int main(int argc, char** argv) {
///     rigger::skill_sdk::SkillRegistry skills;
///     skills.add<MySkill>();
///     return rigger::skill_sdk::run_executor(argc, argv, {"my_skills", "Hosts MySkill."}, std::move(skills));
///   }
///
/// The process is a rigger service of kind skill_executor, like the shipped one: `--config`, `--domain`, `--id` and the cell's
/// environment as every service takes them (docs/deploy.md); it announces the skills its configuration
/// names ("skills", default all of `skills`), runs one at a time per START the task controller sends,
/// and turns SHUTDOWN and PAUSE into the running skill's safe stop and hold. `--describe` prints the
/// skill library of its configuration (offline recipe validation) and exits without DDS.

#include <string>

#include "rigger/skill_sdk/skill_registry.hpp"

namespace rigger::skill_sdk {

struct ExecutorInfo {
  std::string program;      ///< the program's name, in --help and in its log
  std::string description;  ///< one line for --help
};

/// Runs the executor until SIGINT or SIGTERM. Returns the process's exit code: 0 after a clean stop, 2
/// for bad arguments or configuration (an unknown skill, a bad key: the message says which), 1 when
/// DDS failed.
int run_executor(int argc, char** argv, const ExecutorInfo& info, SkillRegistry skills);

}  // namespace rigger::skill_sdk
