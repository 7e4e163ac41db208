#pragma once
/// @file
/// The scripted operator's rules: which prompt gets which answer, after how long. Pure C++ (no DDS).
///
/// A rule (configuration object; every key optional except "answer"):
///   "kind":          prompt kind to match ("screw", "decision", …); absent, "" or "*": any kind
///   "task_id":       exact task id to match; absent: any
///   "node_id":       exact node id to match; absent: any
///   "match_details": object of key → scalar; every key must be in the prompt's details_json with an
///                    equal value (a string "60" equals the number 60)
///   "answer":        string, or array of strings: the first one the prompt offers is given
///   "delay_s":       number in [0, 3600], default 0: how long the "operator" takes
///   "comment":       text sent with the answer
///
/// On the command line a rule reads `KIND[:KEY=VALUE,KEY=VALUE…]:ANSWER[|ANSWER…][@DELAY_S]`, e.g.
/// `screw:hole=h2:failed@0.5`, `screw:done@1`, `decision:retry|continue`, `*:done`.

#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "rigger/base/config.hpp"
#include "rigger/base/settings.hpp"
#include "rigger/operator_protocol/prompt.hpp"
#include "rigger/scripted_operator/settings.hpp"

namespace rigger::scripted_operator {

using operator_protocol::Prompt;

struct Rule {
  std::string kind;  ///< empty: any kind
  std::string task_id;
  std::string node_id;
  nlohmann::json match_details = nlohmann::json::object();
  std::vector<std::string> answers;  ///< in order of preference; never empty
  double delay_s = 0.0;
  std::string comment;
  std::string origin;  ///< where the rule was defined (file and JSON pointer, or the --rule text), for logs
};

/// The fixed options of prompt kinds that have them ("screw": done, failed, abort, from the Screw skill;
/// "confirm": done, abort, from CollaborativeMoveLoad); empty for kinds
/// whose options come with each prompt ("decision": the recipe's labels).
const std::vector<std::string>& known_options(const std::string& kind);

/// Reads one rule object. @throws ConfigError naming the key, e.g. an answer a "screw" prompt never offers.
Rule parse_rule(const Config& config);
/// The scripted operator's configuration (scripted_operator_settings()).
struct ScriptedOperatorSettings {
  std::vector<Rule> rules;  ///< the configuration file's, tried after the --rule ones
  std::string operator_id;  ///< the OperatorResponse's operator_id
};
/// Parses the command-line form (see the file comment). @throws ConfigError whose file is "--rule '<text>'".
Rule parse_rule_argument(const std::string& text);

/// The task controller's question before it resumes a task after a crash (docs/operator.md).
inline constexpr const char* kResumeKind = "resume";

/// Whether `rule` applies to `prompt` (kind, ids, details); a wildcard kind never matches a `resume`
/// prompt (a rule must name it). Does not look at the answer or at `active`.
bool matches(const Rule& rule, const Prompt& prompt);
/// The first rule that matches `prompt`, or nullptr.
const Rule* first_match(const std::vector<Rule>& rules, const Prompt& prompt);
/// The first of the rule's answers the prompt offers, or nullopt (the rule must not answer then).
std::optional<std::string> choose_answer(const Rule& rule, const Prompt& prompt);

/// One line for logs: "screw h1 M12x40 60 N m", "decision 'Which way?' [joystick|visual servo|abort]".
std::string describe(const Prompt& prompt);
/// "done|failed|abort".
std::string join(const std::vector<std::string>& items, const std::string& separator);

}  // namespace rigger::scripted_operator
