#include "rigger/operator_protocol/prompt.hpp"

#include "rigger/dds/conversions.hpp"

namespace rigger::operator_protocol {

Prompt from_wire(const rigger_operator_ui_OperatorPrompt& wire) {
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

Response from_wire(const rigger_operator_ui_OperatorResponse& wire) {
  return {dds::to_string(wire.prompt_id), dds::to_string(wire.answer), dds::to_string(wire.operator_id),
          dds::to_string(wire.comment)};
}

dds_return_t write_prompt(dds::Writer<rigger_operator_ui_OperatorPrompt>& prompts, const Prompt& prompt) {
  rigger_operator_ui_OperatorPrompt p{};
  std::vector<char*> options;
  p.prompt_id = dds::wire_string(prompt.prompt_id);
  p.task_id = dds::wire_string(prompt.task_id);
  p.node_id = dds::wire_string(prompt.node_id);
  p.kind = dds::wire_string(prompt.kind);
  p.title = dds::wire_string(prompt.title);
  p.text = dds::wire_string(prompt.text);
  dds::wire_string_sequence(p.options, prompt.options, options);
  p.details_json = dds::wire_string(prompt.details_json);
  p.timeout_s = prompt.timeout_s;
  p.active = prompt.active;
  p.stamp = dds::wire_now();
  return prompts.write(p);
}

dds_return_t write_response(dds::Writer<rigger_operator_ui_OperatorResponse>& responses, const std::string& prompt_id,
                            const std::string& answer, const std::string& operator_id, const std::string& comment) {
  rigger_operator_ui_OperatorResponse r{};
  r.prompt_id = dds::wire_string(prompt_id);
  r.answer = dds::wire_string(answer);
  r.operator_id = dds::wire_string(operator_id);
  r.comment = dds::wire_string(comment);
  r.stamp = dds::wire_now();
  return responses.write(r);
}

}  // namespace rigger::operator_protocol
