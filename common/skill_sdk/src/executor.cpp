#include "rigger/skill_sdk/executor.hpp"

#include <cstring>
#include <iostream>

#include "executor_node.hpp"

namespace rigger::skill_sdk {
namespace {

int describe(int argc, char** argv, const ExecutorInfo& info, const SkillRegistry& skills) {
  CLI::App app{"Prints the skill library of this executor's configuration.", info.program};
  std::string config_path;
  bool describe_flag = false;
  app.add_flag("--describe", describe_flag, "Print the skill library JSON and exit");
  app.add_option("--config", config_path, "Configuration file (JSON); its \"skills\" select the library");
  app.allow_extras();
  try {
    app.parse(argc, argv);
    const Config config = config_path.empty() ? Config::empty() : Config::load(config_path);
    ExecutorSettings settings;
    read_into(config, executor_settings(info.program, skills), settings);
    std::cout << skills.library_json(settings.skills).dump(2) << "\n";
    return service::kExitOk;
  } catch (const CLI::ParseError& e) {
    return app.exit(e) == 0 ? service::kExitOk : service::kExitUsage;
  } catch (const std::exception& e) {
    std::cerr << info.program << ": " << e.what() << "\n";
    return service::kExitUsage;
  }
}

}  // namespace

int run_executor(int argc, char** argv, const ExecutorInfo& info, SkillRegistry skills) {
  for (int i = 1; i < argc; ++i)
    if (std::strcmp(argv[i], "--describe") == 0) return describe(argc, argv, info, skills);
  // Announced as a skill executor (the kind the controller, the console and the security grants know);
  // the program's own name heads its --help.
  return service::run_service(
      argc, argv,
      {"skill_executor", info.program + ": " + info.description,
       [](CLI::App& app) { app.add_flag("--describe", "Print the skill library JSON of --config and exit (no DDS)"); },
       [&skills](service::ServiceContext& ctx) {
         return std::make_unique<SkillExecutorNode>(ctx, std::move(skills));
       }});
}

}  // namespace rigger::skill_sdk
