#include "operator_decisions.hpp"

#include <limits>

#include "rigger/dds/conversions.hpp"
#include "rigger/dds/qos.hpp"

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
  rigger_operator_ui_OperatorPrompt p{};
  const std::string prompt_id = id.str();
  std::vector<char*> storage;
  p.prompt_id = dds::wire_string(prompt_id);
  p.task_id = dds::wire_string(id.task_id);
  p.node_id = dds::wire_string(spec.id);
  p.kind = dds::wire_string(kind);
  p.title = dds::wire_string(spec.name);
  p.text = dds::wire_string(spec.prompt);
  dds::wire_string_sequence(p.options, spec.options, storage);
  p.details_json = dds::wire_string(details_json);
  p.timeout_s = 0;
  p.active = active;
  p.stamp = dds::wire_now();
  return prompts_.write(p) == DDS_RETCODE_OK;
}

}  // namespace rigger::task_controller
