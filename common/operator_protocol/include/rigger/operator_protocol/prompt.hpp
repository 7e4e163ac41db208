#pragma once
/// @file
/// rigger/operator/prompt and rigger/operator/response (idl/operator.idl) in domain form, converted to
/// and from the wire here once for everyone who asks, shows or answers prompts: the task controller
/// and the skills' operator panel ask; scripted_operator, riggerctl operator and the console show and
/// answer.

#include <string>
#include <vector>

#include "rigger/dds/pubsub.hpp"
#include "rigger/idl/operator.h"
#include "rigger/protocol/operator.hpp"

namespace rigger::operator_protocol {

/// A prompt as the operator sees it: the domain form of OperatorPrompt.
struct Prompt {
  std::string prompt_id;
  std::string task_id;
  std::string node_id;
  std::string kind;
  std::string title;
  std::string text;
  std::vector<std::string> options;
  std::string details_json;  ///< a JSON object, or empty
  double timeout_s = 0.0;
  bool active = false;  ///< false: the prompt was withdrawn or answered
};

/// An operator's answer to a prompt: the domain form of OperatorResponse.
struct Response {
  std::string prompt_id;
  std::string answer;  ///< one of the prompt's options
  std::string operator_id;
  std::string comment;
};

Prompt from_wire(const rigger_operator_ui_OperatorPrompt& wire);
Response from_wire(const rigger_operator_ui_OperatorResponse& wire);

/// Writes `prompt` (stamped now) on `prompts`, a writer of protocol::operator_ui::kPrompt; returns the
/// DDS return code.
dds_return_t write_prompt(dds::Writer<rigger_operator_ui_OperatorPrompt>& prompts, const Prompt& prompt);

/// Writes `operator_id`'s `answer` to prompt `prompt_id` (stamped now) on `responses`, a writer of
/// protocol::operator_ui::kResponse; returns the DDS return code.
dds_return_t write_response(dds::Writer<rigger_operator_ui_OperatorResponse>& responses, const std::string& prompt_id,
                            const std::string& answer, const std::string& operator_id, const std::string& comment);

}  // namespace rigger::operator_protocol
