#include "rigger/operator_ui/prompt.hpp"

#include "rigger/dds/conversions.hpp"

namespace rigger::operator_ui {

Prompt to_domain(const rigger_operator_ui_OperatorPrompt& wire) {
  Prompt p;
  p.prompt_id = dds::to_string(wire.prompt_id);
  p.task_id = dds::to_string(wire.task_id);
  p.node_id = dds::to_string(wire.node_id);
  p.kind = dds::to_string(wire.kind);
  p.title = dds::to_string(wire.title);
  p.text = dds::to_string(wire.text);
  p.options = dds::to_string_vector(wire.options);
  p.details_json = dds::to_string(wire.details_json);
  p.timeout_s = wire.timeout_s;
  p.active = wire.active;
  return p;
}

}  // namespace rigger::operator_ui
