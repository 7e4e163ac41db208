#pragma once
/// @file
/// The scripted operator's DDS node: reads rigger/operator/prompt, answers each active prompt once by
/// the first matching rule (rules.hpp) on rigger/operator/response after the rule's delay (an event-loop
/// timer). It never answers an option the prompt does not offer (it logs an error instead), never
/// withdraws a prompt, and drops a pending answer when the prompt is withdrawn or someone else answers.
///
/// Configuration keys: scripted_operator_settings() (rigger/scripted_operator/settings.hpp).
///
/// Command line: --rule 'KIND[:KEY=VALUE,…]:ANSWER[|ANSWER…][@DELAY_S]' (repeatable); these rules come
/// first, so they override the configuration file's for the prompts they match.

#include <map>
#include <set>
#include <string>
#include <vector>

#include "rigger/dds/pubsub.hpp"
#include "rigger/service/service.hpp"
#include "rules.hpp"

namespace rigger::scripted_operator {

class ScriptedOperatorNode : public service::Node {
 public:
  /// @param rule_arguments the --rule texts, in order. @throws ConfigError for a bad rule (exit 2).
  ScriptedOperatorNode(service::ServiceContext& ctx, const std::vector<std::string>& rule_arguments);
  ~ScriptedOperatorNode() override;

 private:
  struct Pending {
    dds::EventLoop::TimerId timer = 0;
    std::string answer;
    const Rule* rule = nullptr;
    std::string description;
  };

  void on_prompts();
  void on_prompt(const Prompt& prompt);
  void on_responses();
  void answer(const std::string& prompt_id);

  service::ServiceContext& ctx_;
  std::vector<Rule> rules_;
  std::string operator_id_;
  dds::Reader<rigger_operator_ui_OperatorPrompt> prompts_;
  dds::Reader<rigger_operator_ui_OperatorResponse> responses_in_;
  dds::Writer<rigger_operator_ui_OperatorResponse> responses_;
  std::map<std::string, Pending> pending_;  ///< prompt id → the answer waiting for its delay
  std::set<std::string> done_;              ///< prompt ids answered, answered by others, or left alone
};

}  // namespace rigger::scripted_operator
