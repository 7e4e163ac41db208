#include "scripted_operator_node.hpp"

#include <chrono>

#include "rigger/base/time.hpp"
#include "rigger/dds/conversions.hpp"
#include "rigger/protocol/operator.hpp"

namespace rigger::scripted_operator {
ScriptedOperatorNode::ScriptedOperatorNode(service::ServiceContext& ctx, const std::vector<std::string>& rule_arguments)
    : ctx_(ctx),
      prompts_(ctx.participant, protocol::operator_ui::kPrompt),
      responses_in_(ctx.participant, protocol::operator_ui::kResponse),
      responses_(ctx.participant, protocol::operator_ui::kResponse) {
  for (const auto& text : rule_arguments) rules_.push_back(parse_rule_argument(text));
  ScriptedOperatorSettings settings = read_settings(ctx.config, scripted_operator_settings());
  for (auto& rule : settings.rules) rules_.push_back(std::move(rule));
  operator_id_ = std::move(settings.operator_id);

  for (const auto& rule : rules_)
    ctx.log->info("rule kind={} task={} node={} details={} answer={} delay_s={} from={}",
                  rule.kind.empty() ? "*" : rule.kind, rule.task_id.empty() ? "*" : rule.task_id,
                  rule.node_id.empty() ? "*" : rule.node_id, rule.match_details.dump(), join(rule.answers, "|"),
                  rule.delay_s, rule.origin);
  if (rules_.empty()) ctx.log->warn("no rules: every prompt is left for a human");
  ctx.loop.on_data(prompts_, [this] { on_prompts(); });
  ctx.loop.on_data(responses_in_, [this] { on_responses(); });
  ctx.log->info("scripted operator ready rules={} operator_id={}", rules_.size(), operator_id_);
}

ScriptedOperatorNode::~ScriptedOperatorNode() {
  for (const auto& [id, p] : pending_) ctx_.loop.cancel(p.timer);
}

void ScriptedOperatorNode::on_prompts() {
  prompts_.take([this](const rigger_operator_ui_OperatorPrompt& p,
                       const dds_sample_info_t&) { on_prompt(operator_protocol::from_wire(p)); },
                [this](const rigger_operator_ui_OperatorPrompt& key, const dds_sample_info_t& info) {
                  // A disposed prompt instance is gone for good: forget it (its id may be reused).
                  if (info.instance_state != DDS_IST_NOT_ALIVE_DISPOSED) return;
                  const std::string id = dds::to_string(key.prompt_id);
                  if (auto it = pending_.find(id); it != pending_.end()) {
                    ctx_.loop.cancel(it->second.timer);
                    pending_.erase(it);
                  }
                  done_.erase(id);
                });
}

void ScriptedOperatorNode::on_prompt(const Prompt& prompt) {
  const std::string& id = prompt.prompt_id;
  if (!prompt.active) {
    if (auto it = pending_.find(id); it != pending_.end()) {
      ctx_.log->info("prompt {} withdrawn before the answer id={}", it->second.description, id);
      ctx_.loop.cancel(it->second.timer);
      pending_.erase(it);  // never answered: a later re-activation gets an answer
    }
    return;
  }
  if (pending_.count(id) || done_.count(id)) return;  // once per prompt id
  const std::string description = describe(prompt);
  const Rule* rule = first_match(rules_, prompt);
  if (!rule) {
    ctx_.log->info("prompt {} -> no rule matches: left for a human id={}", description, id);
    done_.insert(id);
    return;
  }
  const auto chosen = choose_answer(*rule, prompt);
  if (!chosen) {
    ctx_.log->error("prompt {} -> rule {} answers {} but the prompt offers {}: not answering id={}", description,
                    rule->origin, join(rule->answers, "|"), join(prompt.options, "|"), id);
    done_.insert(id);
    return;
  }
  if (prompt.timeout_s > 0 && rule->delay_s >= prompt.timeout_s)
    ctx_.log->warn("prompt {} -> rule {} waits {:.1f} s but the prompt times out after {:.1f} s id={}", description,
                   rule->origin, rule->delay_s, prompt.timeout_s, id);
  Pending& p = pending_[id];
  p.answer = *chosen;
  p.rule = rule;
  p.description = description;
  p.timer = ctx_.loop.after(from_seconds(rule->delay_s), [this, id] { answer(id); });
  ctx_.log->debug("prompt {} -> {} in {:.1f} s id={} rule={}", description, *chosen, rule->delay_s, id, rule->origin);
}

void ScriptedOperatorNode::answer(const std::string& prompt_id) {
  auto it = pending_.find(prompt_id);
  if (it == pending_.end()) return;
  const Pending p = it->second;
  pending_.erase(it);
  done_.insert(prompt_id);
  if (const auto rc = operator_protocol::write_response(responses_, prompt_id, p.answer, operator_id_, p.rule->comment);
      rc != DDS_RETCODE_OK) {
    ctx_.log->error("response write failed id={} rc={}", prompt_id, dds_strretcode(rc));
    return;
  }
  ctx_.log->info("prompt {} -> {} after {:.1f} s id={}", p.description, p.answer, p.rule->delay_s, prompt_id);
}

void ScriptedOperatorNode::on_responses() {
  responses_in_.take([this](const rigger_operator_ui_OperatorResponse& r, const dds_sample_info_t&) {
    const std::string id = dds::to_string(r.prompt_id);
    const std::string by = dds::to_string(r.operator_id);
    auto it = pending_.find(id);
    if (it == pending_.end() || by == operator_id_) return;
    ctx_.log->info("prompt {} answered by {} ({}) first: dropping ours id={}", it->second.description, by,
                   dds::to_string(r.answer), id);
    ctx_.loop.cancel(it->second.timer);
    pending_.erase(it);
    done_.insert(id);
  });
}

}  // namespace rigger::scripted_operator
