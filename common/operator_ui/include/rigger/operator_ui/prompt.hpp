#pragma once
/// @file
/// The operator's side of rigger/operator/prompt and rigger/operator/response (idl/operator.idl):
/// topic names, a prompt in domain form (std::string, std::vector) converted from the wire once, and
/// the answer written back.

#include <string>
#include <vector>

#include "rigger/dds/pubsub.hpp"
#include "rigger/idl/operator.h"
#include "rigger/protocol/operator.hpp"

namespace rigger::operator_ui {

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

Prompt to_domain(const rigger_operator_ui_OperatorPrompt& wire);

/// Writes `operator_id`'s `answer` to prompt `prompt_id` (stamped now) on `responses`, a writer of
/// protocol::operator_ui::kResponse; returns the DDS return code.
dds_return_t write_response(dds::Writer<rigger_operator_ui_OperatorResponse>& responses, const std::string& prompt_id,
                            const std::string& answer, const std::string& operator_id, const std::string& comment);

}  // namespace rigger::operator_ui
