#include <memory>

#include "scripted_operator_node.hpp"

int main(int argc, char** argv) {
  auto rules = std::make_shared<std::vector<std::string>>();
  return rigger::service::run_service(
      argc, argv,
      {"scripted_operator", "Answers operator prompts by rule (the demo's and the tests' human).",
       [rules](CLI::App& app) {
         app.add_option("--rule", *rules,
                        "Rule KIND[:KEY=VALUE,...]:ANSWER[|ANSWER...][@DELAY_S], e.g. 'screw:hole=h2:failed@0.5'; "
                        "repeatable, tried in order before the configuration file's rules")
             ->expected(1)
             ->multi_option_policy(CLI::MultiOptionPolicy::TakeAll);
       },
       [rules](rigger::service::ServiceContext& ctx) {
         return std::make_unique<rigger::scripted_operator::ScriptedOperatorNode>(ctx, *rules);
       }});
}
