#include "catalog.hpp"

#include <sstream>

#include "rigger/monitor_host/library.hpp"
#include "rigger/recipe/conditions.hpp"
#include "rigger/skill_executor/library.hpp"

namespace rigger::catalog {
namespace {

void append_kind(nlohmann::json& skills, const nlohmann::json& library) {
  for (const auto& s : library.at("skills")) skills.push_back(s);
}

std::string number(const nlohmann::json& v) {
  std::ostringstream out;
  if (v.is_number_integer()) {
    out << v.get<long long>();
  } else {
    out << v.get<double>();
  }
  return out.str();
}

std::string range_text(const nlohmann::json& p) {
  const bool lo = p.contains("min"), hi = p.contains("max");
  if (!lo && !hi) return "";
  const std::string type = p.value("type", "");
  const bool count = type == "string" || type == "string_list";
  std::string out = count ? (type == "string" ? "length " : "items ") : type == "number_list" ? "each " : "";
  if (lo && hi) return out + "[" + number(p["min"]) + ", " + number(p["max"]) + "]";
  if (lo) return out + "≥ " + number(p["min"]);
  return out + "≤ " + number(p["max"]);
}

std::string escape_cell(std::string s) {
  std::string out;
  for (char c : s) out += (c == '|') ? std::string("\\|") : std::string(1, c);
  return out;
}

std::string join(const nlohmann::json& list) {
  std::string out;
  for (const auto& item : list) out += (out.empty() ? "`" : ", `") + item.get<std::string>() + "`";
  return out;
}

}  // namespace

nlohmann::json library_json() {
  nlohmann::json skills = nlohmann::json::array();
  append_kind(skills, skill_executor::builtin_skill_library_json());
  append_kind(skills, monitor::monitor_library_json());
  append_kind(skills, recipe::controller_conditions_json());
  return {{"library_version", 1},
          {"description",
           "Every skill, monitor and condition built into rigger, generated from their descriptions by "
           "tools/update-skill-library (do not edit by hand; a unit test checks it is current)."},
          {"skills", skills}};
}

std::string reference_markdown(const nlohmann::json& library) {
  std::ostringstream md;
  md << "# Skill reference\n\n"
     << "Generated from the descriptions built into the executors, the monitor host and the task\n"
     << "controller by `tools/update-skill-library`; do not edit by hand (a unit test checks it is\n"
     << "current). How recipes use these: [recipes.md](recipes.md); how skills run and how to write one:\n"
     << "[skills.md](skills.md).\n\n"
     << "Quantities may be given as `{\"value\": 3, \"unit\": \"mm\"}`; they are converted to the unit shown.\n"
     << "A parameter without a default is required.\n";
  for (const char* kind : {"skill", "monitor", "condition"}) {
    const std::string heading = std::string(kind) == "skill"     ? "Skills"
                                : std::string(kind) == "monitor" ? "Monitors (never succeed; fail when they detect)"
                                                                 : "Conditions (answered by the controller from the world model)";
    md << "\n## " << heading << "\n";
    for (const auto& s : library.at("skills")) {
      if (s.value("kind", "") != kind) continue;
      md << "\n### " << s.at("name").get<std::string>() << "\n\n";
      if (s.contains("description")) md << s["description"].get<std::string>() << "\n\n";
      if (!s.value("params", nlohmann::json::array()).empty()) {
        md << "| parameter | type | unit | range | default | meaning |\n|---|---|---|---|---|---|\n";
        for (const auto& p : s["params"]) {
          std::string type = p.value("type", "");
          if (p.contains("values")) type += ": " + join(p["values"]);
          md << "| `" << p.at("name").get<std::string>() << "` | " << type << " | " << p.value("unit", "") << " | "
             << range_text(p) << " | " << (p.contains("default") ? "`" + p["default"].dump() + "`" : "required")
             << " | " << escape_cell(p.value("description", "")) << " |\n";
        }
        md << "\n";
      }
      if (!s.value("resources", nlohmann::json::array()).empty())
        md << "- resources: " << join(s["resources"]) << "\n";
      if (!s.value("preconditions", nlohmann::json::array()).empty())
        md << "- preconditions: " << join(s["preconditions"]) << "\n";
      if (!s.value("postconditions", nlohmann::json::array()).empty())
        md << "- postconditions: " << join(s["postconditions"]) << "\n";
      if (std::string(kind) == "skill")
        md << (s.value("pausable", false) ? "- pausable: yes (a PAUSE holds its devices still until RESUME)\n"
                                          : "- pausable: no (it keeps running while its task is paused)\n");
    }
  }
  return md.str();
}

}  // namespace rigger::catalog
