#include "operator_decisions.hpp"

#include <limits>

#include "rigger/dds/conversions.hpp"
#include "rigger/dds/qos.hpp"
#include "rigger/operator_protocol/prompt.hpp"

namespace rigger::task_controller {

std::string PromptId::str() const { return task_id + "#" + node_id + "#" + std::to_string(activation); }

std::optional<PromptId> PromptId::parse(std::string_view text) {
  if (text.size() > kMaxLength) return std::nullopt;
  // Node ids never hold '#' and task ids cannot (the recipe schema's pattern): split at the last two.
  const auto second = text.rfind('#');
  if (second == std::string_view::npos || second == 0) return std::nullopt;
  const auto first = text.rfind('#', second - 1);
  if (first == std::string_view::npos || first == 0 || first + 1 == second) return std::nullopt;
  const std::string_view digits = text.substr(second + 1);
  if (digits.empty() || digits.size() > 10) return std::nullopt;
  std::uint64_t activation = 0;
  for (char c : digits) {
    if (c < '0' || c > '9') return std::nullopt;
    activation = activation * 10 + static_cast<std::uint64_t>(c - '0');
  }
  if (activation > std::numeric_limits<bt::Activation>::max()) return std::nullopt;
  PromptId id;
  id.task_id = std::string(text.substr(0, first));
  id.node_id = std::string(text.substr(first + 1, second - first - 1));
  id.activation = static_cast<bt::Activation>(activation);
  return id;
}

std::optional<std::size_t> option_index(const std::vector<std::string>& options, const std::string& answer) {
  for (std::size_t i = 0; i < options.size(); ++i)
    if (options[i] == answer) return i;
  return std::nullopt;
}

std::string quoted_options(const std::vector<std::string>& options) {
  std::string out;
  for (const auto& o : options) out += (out.empty() ? "\"" : ", \"") + o + "\"";
  return out;
}

PromptWriter::PromptWriter(const dds::Participant& participant)
    : prompts_(participant, protocol::operator_ui::kPrompt) {}

bool PromptWriter::write(const PromptId& id, const bt::NodeSpec& spec, bool active, const std::string& kind,
                         const std::string& details_json) {
  operator_protocol::Prompt p;
  p.prompt_id = id.str();
  p.task_id = id.task_id;
  p.node_id = spec.id;
  p.kind = kind;
  p.title = spec.name;
  p.text = spec.prompt;
  p.options = spec.options;
  p.details_json = details_json;
  p.active = active;
  return operator_protocol::write_prompt(prompts_, p) == DDS_RETCODE_OK;
}

}  // namespace rigger::task_controller
