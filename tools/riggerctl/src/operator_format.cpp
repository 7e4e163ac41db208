#include "operator_format.hpp"

#include <algorithm>
#include <cctype>
#include <cstdio>

#include <nlohmann/json.hpp>

#include "rigger/base/bounded_json.hpp"

namespace rigger::ctl {
namespace {

std::string trim(const std::string& s) {
  const auto b = s.find_first_not_of(" \t\r\n");
  if (b == std::string::npos) return "";
  const auto e = s.find_last_not_of(" \t\r\n");
  return s.substr(b, e - b + 1);
}

std::string lower(std::string s) {
  std::transform(s.begin(), s.end(), s.begin(), [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return s;
}

std::string detail_text(const nlohmann::json& v) {
  if (v.is_string()) return v.get<std::string>();
  if (v.is_number_float()) {
    char buffer[32];
    std::snprintf(buffer, sizeof buffer, "%g", v.get<double>());
    return buffer;
  }
  return v.dump();
}

}  // namespace

std::string format_prompt(const PromptView& p, std::size_t position, std::size_t count) {
  std::string out = "-- prompt " + std::to_string(position) + " of " + std::to_string(count) + ": " + p.prompt_id +
                    "  (" + (p.kind.empty() ? "?" : p.kind);
  if (!p.task_id.empty()) out += ", task " + p.task_id;
  if (!p.node_id.empty()) out += ", node " + p.node_id;
  if (p.timeout_s > 0) {
    char buffer[48];
    std::snprintf(buffer, sizeof buffer, ", timeout %g s", p.timeout_s);
    out += buffer;
  }
  out += ")\n";
  if (!p.title.empty()) out += "   " + p.title + "\n";
  if (!p.text.empty()) out += "   " + p.text + "\n";
  const JsonParseResult parsed = parse_json_bounded(p.details_json, {64U * 1024U, 16});  // from a skill: bounded
  const nlohmann::json details = parsed.ok() ? parsed.value : nlohmann::json::object();
  if (details.is_object() && !details.empty()) {
    for (const auto& [key, value] : details.items()) {
      out += "     " + key + ": " + detail_text(value);
      if (key == "torque_nm") out += " N m";
      out += "\n";
    }
  } else if (!p.details_json.empty() && !details.is_object()) {
    out += "     details: " + p.details_json + "\n";
  }
  for (std::size_t i = 0; i < p.options.size(); ++i) out += "   [" + std::to_string(i + 1) + "] " + p.options[i] + "\n";
  return out;
}

std::optional<std::string> resolve_answer(const std::string& input, const std::vector<std::string>& options) {
  const std::string t = trim(input);
  if (t.empty()) return std::nullopt;
  for (const auto& o : options)
    if (o == t) return o;
  std::optional<std::string> found;
  for (const auto& o : options)
    if (lower(o) == lower(t)) {
      if (found) return std::nullopt;  // ambiguous without case
      found = o;
    }
  if (found) return found;
  if (std::all_of(t.begin(), t.end(), [](unsigned char c) { return std::isdigit(c); }) && t.size() < 6) {
    const auto n = static_cast<std::size_t>(std::stoul(t));
    if (n >= 1 && n <= options.size()) return options[n - 1];
  }
  return std::nullopt;
}

std::optional<std::pair<std::string, std::string>> split_assignment(const std::string& text) {
  const auto eq = text.find('=');
  if (eq == std::string::npos || eq == 0 || eq + 1 == text.size()) return std::nullopt;
  return std::make_pair(text.substr(0, eq), text.substr(eq + 1));
}

}  // namespace rigger::ctl
