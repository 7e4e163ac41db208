#pragma once
/// @file
/// Pure helpers of `riggerctl operator` (no DDS): how a prompt is shown in a terminal and how typed
/// input becomes one of its options.

#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "rigger/operator_protocol/prompt.hpp"

namespace rigger::ctl {

using PromptView = operator_protocol::Prompt;

/// Several lines: header (position, id, kind, task/node), title, text, details as key: value, and the
/// options numbered from 1. Ends with a newline.
std::string format_prompt(const PromptView& prompt, std::size_t position, std::size_t count);

/// The option `input` names: the option itself (exact, then case-insensitive, surrounding blanks
/// ignored), or its number counted from 1. nullopt when it names none.
std::optional<std::string> resolve_answer(const std::string& input, const std::vector<std::string>& options);

/// Splits "PROMPT_ID=ANSWER" at the first '='. nullopt when there is none or either side is empty.
std::optional<std::pair<std::string, std::string>> split_assignment(const std::string& text);

}  // namespace rigger::ctl
