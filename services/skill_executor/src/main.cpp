// skill_executor: hosts the skills its configuration names. `skill_executor --describe [--config F]`
// prints the skill library those skills form (for offline recipe validation) and exits.
#include <cstring>
#include <iostream>

#include "skill_executor_node.hpp"

namespace {

int describe(int argc, char** argv) {
  CLI::App app{"Prints the skill library of this executor's configuration.", "skill_executor"};
  std::string config_path;
  bool describe_flag = false;
  app.add_flag("--describe", describe_flag, "Print the skill library JSON and exit");
  app.add_option("--config", config_path, "Configuration file (JSON); its \"skills\" select the library");
  app.allow_extras();
  try {
    app.parse(argc, argv);
    const auto registry = rigger::skill_executor::builtin_skills();
    const rigger::Config config = config_path.empty() ? rigger::Config::empty() : rigger::Config::load(config_path);
    std::cout << registry.library_json(rigger::skill_executor::configured_skills(config, registry)).dump(2) << "\n";
    return rigger::dds::kExitOk;
  } catch (const CLI::ParseError& e) {
    return app.exit(e) == 0 ? rigger::dds::kExitOk : rigger::dds::kExitUsage;
  } catch (const std::exception& e) {
    std::cerr << "skill_executor: " << e.what() << "\n";
    return rigger::dds::kExitUsage;
  }
}

}  // namespace

int main(int argc, char** argv) {
  for (int i = 1; i < argc; ++i)
    if (std::strcmp(argv[i], "--describe") == 0) return describe(argc, argv);
  return rigger::dds::run_service(
      argc, argv,
      {"skill_executor", "Hosts the skills its configuration names (--describe prints their library).",
       [](CLI::App& app) {
         app.add_flag("--describe", "Print the skill library JSON of --config and exit (no DDS)");
       },
       [](rigger::dds::ServiceContext& ctx) {
         return std::make_unique<rigger::skill_executor::SkillExecutorNode>(ctx,
                                                                            rigger::skill_executor::builtin_skills());
       }});
}
