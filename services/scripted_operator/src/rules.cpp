#include "rules.hpp"

#include "rigger/base/bounded_json.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <map>

namespace rigger::scripted_operator {
namespace {

using nlohmann::json;

std::vector<std::string> split(const std::string& text, char separator) {
  std::vector<std::string> parts;
  std::string::size_type start = 0;
  for (;;) {
    const auto end = text.find(separator, start);
    parts.push_back(text.substr(start, end == std::string::npos ? std::string::npos : end - start));
    if (end == std::string::npos) return parts;
    start = end + 1;
  }
}

std::optional<double> parse_number(const std::string& text) {
  if (text.empty()) return std::nullopt;
  char* end = nullptr;
  const double v = std::strtod(text.c_str(), &end);
  if (*end != '\0' || !std::isfinite(v)) return std::nullopt;
  return v;
}

/// Scalars compare by value; a string that spells a number or a boolean equals that number or boolean
/// (command-line rules carry every value as a string).
bool scalar_equal(const json& expected, const json& actual) {
  if (expected == actual) return true;
  const json* s = expected.is_string() ? &expected : actual.is_string() ? &actual : nullptr;
  const json* other = s == &expected ? &actual : &expected;
  if (!s) return false;
  const std::string text = s->get<std::string>();
  if (other->is_number()) {
    const auto v = parse_number(text);
    return v && *v == other->get<double>();
  }
  if (other->is_boolean()) return text == (other->get<bool>() ? "true" : "false");
  return false;
}

std::string format_number(double v) {
  char buffer[32];
  std::snprintf(buffer, sizeof buffer, "%g", v);
  return buffer;
}

std::string scalar_text(const json& v) {
  if (v.is_string()) return v.get<std::string>();
  if (v.is_number()) return format_number(v.get<double>());
  return v.dump();
}

}  // namespace

const std::vector<std::string>& known_options(const std::string& kind) {
  static const std::map<std::string, std::vector<std::string>> kKnown{{"screw", {"done", "failed", "abort"}},
                                                                      {"confirm", {"done", "abort"}}};
  static const std::vector<std::string> kNone;
  const auto it = kKnown.find(kind);
  return it == kKnown.end() ? kNone : it->second;
}

Rule parse_rule(const Config& config) {
  Rule rule;
  rule.origin = config.file() + " at " + (config.pointer().empty() ? "/" : config.pointer());
  rule.kind = config.get<std::string>("kind", "");
  if (rule.kind == "*") rule.kind.clear();
  rule.task_id = config.get<std::string>("task_id", "");
  rule.node_id = config.get<std::string>("node_id", "");
  if (config.has("match_details")) {
    const json& details = config.raw("match_details");
    if (!details.is_object()) config.fail("match_details", "expected an object of detail key → value");
    for (const auto& [key, value] : details.items())
      if (!value.is_primitive() || value.is_null())
        config.fail("match_details", "expected a string, number or boolean for \"" + key + "\", got " + value.dump());
    rule.match_details = details;
  }
  if (!config.has("answer")) config.fail("answer", "missing: the answer this rule gives (a string or an array)");
  const json& answer = config.raw("answer");
  if (answer.is_string()) {
    rule.answers.push_back(answer.get<std::string>());
  } else if (answer.is_array() && !answer.empty()) {
    for (const auto& a : answer) {
      if (!a.is_string()) config.fail("answer", "expected an array of strings, got " + a.dump());
      rule.answers.push_back(a.get<std::string>());
    }
  } else {
    config.fail("answer", "expected a string or a non-empty array of strings, got " + answer.dump());
  }
  const auto& offered = known_options(rule.kind);
  for (const auto& a : rule.answers) {
    if (a.empty()) config.fail("answer", "expected a non-empty answer");
    if (!offered.empty() && std::find(offered.begin(), offered.end(), a) == offered.end())
      config.fail("answer", "\"" + a + "\" is not an option of a \"" + rule.kind + "\" prompt (expected one of " +
                                join(offered, ", ") + ")");
  }
  rule.delay_s = config.get_in_range<double>("delay_s", 0.0, 0.0, 3600.0);
  rule.comment = config.get<std::string>("comment", "");
  return rule;
}

const SettingsTable<ScriptedOperatorSettings>& scripted_operator_settings() {
  using S = ScriptedOperatorSettings;
  static const SettingsTable<S> table{
      own_setting<S>(
          "rules", "array of rule objects", "[]", "",
          [](const Config& config, const std::string& key, S& s) {
            if (config.has(key) && !config.raw(key).is_array()) config.fail(key, "expected an array of rule objects");
            for (const auto& child : config.children(key)) s.rules.push_back(parse_rule(child));
          },
          "tried in order after the `--rule` ones; a rule's keys (`kind`, `task_id`, `node_id`, `match_details`, "
          "`answer`, `delay_s`, `comment`) in [operator.md](operator.md#rules)"),
      setting<S>(
          "operator_id", "scripted",
          [](S& s, const std::string& id, const Config& config) {
            if (id.empty()) config.fail("operator_id", "expected a non-empty operator id");
            s.operator_id = id;
          },
          "the `operator_id` of its answers; not empty"),
  };
  return table;
}

Rule parse_rule_argument(const std::string& text) {
  const std::string origin = "--rule '" + text + "'";
  const auto fail = [&](const std::string& problem) {
    throw ConfigError(origin, "", problem + " (expected KIND[:KEY=VALUE,…]:ANSWER[|ANSWER…][@DELAY_S])");
  };
  const auto parts = split(text, ':');
  if (parts.size() < 2 || parts.size() > 3) fail("expected 2 or 3 fields separated by ':'");
  json rule = json::object();
  rule["kind"] = parts[0];
  if (parts.size() == 3) {
    json details = json::object();
    for (const auto& pair : split(parts[1], ',')) {
      const auto eq = pair.find('=');
      if (eq == std::string::npos || eq == 0) fail("detail match '" + pair + "' is not KEY=VALUE");
      details[pair.substr(0, eq)] = pair.substr(eq + 1);
    }
    rule["match_details"] = details;
  }
  std::string answer = parts.back();
  if (const auto at = answer.rfind('@'); at != std::string::npos) {
    const std::string delay = answer.substr(at + 1);
    const auto seconds =
        parse_number(delay.size() > 1 && delay.back() == 's' ? delay.substr(0, delay.size() - 1) : delay);
    // An unreadable delay goes in as text, so that the rule parser reports it at /delay_s.
    rule["delay_s"] = seconds ? json(*seconds) : json(delay);
    answer = answer.substr(0, at);
  }
  rule["answer"] = split(answer, '|');
  Config config = Config::parse(rule.dump(), origin);
  Rule parsed = parse_rule(config);
  config.finish();
  parsed.origin = origin;
  return parsed;
}

// A prompt's details arrive over DDS from another process: parsed bounded, anything else is no details.
json details_of(const Prompt& prompt) {
  auto parsed = parse_json_bounded(prompt.details_json, JsonLimits{64U * 1024U, 16});
  return parsed.ok() ? std::move(parsed.value) : json();
}

bool matches(const Rule& rule, const Prompt& prompt) {
  if (!rule.kind.empty() && rule.kind != prompt.kind) return false;
  // Confirming a resume after a controller crash restarts motion: only a rule that names it answers.
  if (rule.kind.empty() && prompt.kind == kResumeKind) return false;
  if (!rule.task_id.empty() && rule.task_id != prompt.task_id) return false;
  if (!rule.node_id.empty() && rule.node_id != prompt.node_id) return false;
  if (rule.match_details.empty()) return true;
  const json details = details_of(prompt);
  if (!details.is_object()) return false;
  for (const auto& [key, expected] : rule.match_details.items()) {
    const auto it = details.find(key);
    if (it == details.end() || !scalar_equal(expected, *it)) return false;
  }
  return true;
}

const Rule* first_match(const std::vector<Rule>& rules, const Prompt& prompt) {
  for (const auto& rule : rules)
    if (matches(rule, prompt)) return &rule;
  return nullptr;
}

std::optional<std::string> choose_answer(const Rule& rule, const Prompt& prompt) {
  for (const auto& a : rule.answers)
    if (std::find(prompt.options.begin(), prompt.options.end(), a) != prompt.options.end()) return a;
  return std::nullopt;
}

std::string describe(const Prompt& prompt) {
  std::string line = prompt.kind.empty() ? "(no kind)" : prompt.kind;
  const json details = details_of(prompt);
  bool any_detail = false;
  if (details.is_object()) {
    // The screw prompt's well-known fields first, in reading order, then the rest as key=value.
    for (const char* key : {"hole", "screw_type"})
      if (auto it = details.find(key); it != details.end()) {
        line += " " + scalar_text(*it);
        any_detail = true;
      }
    if (auto it = details.find("torque_nm"); it != details.end()) {
      line += " " + scalar_text(*it) + " N m";
      any_detail = true;
    }
    for (const auto& [key, value] : details.items()) {
      if (key == "hole" || key == "screw_type" || key == "torque_nm") continue;
      line += " " + key + "=" + scalar_text(value);
      any_detail = true;
    }
  }
  if (!any_detail) {
    const std::string& what = prompt.text.empty() ? prompt.title : prompt.text;
    if (!what.empty()) line += " '" + what + "'";
  }
  if (known_options(prompt.kind).empty()) line += " [" + join(prompt.options, "|") + "]";
  return line;
}

std::string join(const std::vector<std::string>& items, const std::string& separator) {
  std::string out;
  for (std::size_t i = 0; i < items.size(); ++i) out += (i ? separator : "") + items[i];
  return out;
}

}  // namespace rigger::scripted_operator
