#include "scripted_settings.hpp"

#include <filesystem>
#include <set>
#include <vector>

#include "rigger/base/bounded_json.hpp"

namespace rigger::scripted {
namespace {

using S = ScriptedExecutorSettings;

void load_library(S& s, const std::filesystem::path& path, const Config& config) {
  auto parsed = parse_json_file_bounded(path);
  if (!parsed.ok()) config.fail("library_file", parsed.error->to_string());
  s.library = std::move(parsed.value);
  if (!s.library.contains("skills") || !s.library["skills"].is_array())
    config.fail("library_file", "expected a skill library with a \"skills\" array");
  for (const auto& d : s.library["skills"]) s.is_monitor[d.value("name", "")] = d.value("kind", "skill") == "monitor";
}

/// Keeps the library's descriptions named in `wanted` (every one when it is empty).
void announce_only(S& s, const std::vector<std::string>& names, const Config& config) {
  if (names.empty()) return;
  const std::set<std::string> wanted(names.begin(), names.end());
  std::set<std::string> missing = wanted;
  nlohmann::json skills = nlohmann::json::array();
  s.is_monitor.clear();
  for (const auto& d : s.library["skills"]) {
    const std::string name = d.value("name", "");
    if (!wanted.count(name)) continue;
    s.is_monitor[name] = d.value("kind", "skill") == "monitor";
    missing.erase(name);
    skills.push_back(d);
  }
  if (!missing.empty()) config.fail("skills", "not in the library: " + *missing.begin());
  s.library["skills"] = skills;
}

/// The object `key` of `config`, checked to be one (absent: none).
std::vector<std::pair<std::string, Config>> members(const Config& config, const std::string& key,
                                                    const std::string& expected) {
  std::vector<std::pair<std::string, Config>> out;
  if (!config.has(key)) return out;
  const auto& raw = config.raw(key);
  if (!raw.is_object()) config.fail(key, "expected an object: " + expected);
  const Config children = config.child(key);
  for (const auto& item : raw.items()) out.emplace_back(item.key(), children.child(item.key()));
  return out;
}

}  // namespace

const SettingsTable<ScriptedExecutorSettings>& scripted_executor_settings() {
  static const SettingsTable<S> table{
      path_setting<S>("library_file", "test/data/scripted_skill_library.json", &load_library,
                      "the skill library announced: relative to this file, then to the data folder"),
      setting<S>("skills", std::vector<std::string>{}, &announce_only,
                 "the names announced; `[]`: every description in the library"),
      own_setting<S>(
          "default", "behaviour object", "{}", "",
          [](const Config& config, const std::string& key, S& s) {
            s.default_skill = parse_behaviour(config.child_or_empty(key), Behaviour{});
            s.default_monitor.mode = Mode::kRun;
          },
          "what a skill does once started (`mode`, `delay_s`, `code`, `message`, `progress_steps`, "
          "`stop_delay_s`, `never_stop`: `services/scripted_executor/src/behaviour.hpp`); monitors run"),
      own_setting<S>(
          "behaviours", "object: skill name → behaviour", "{}", "",
          [](const Config& config, const std::string& key, S& s) {
            for (const auto& [name, behaviour] : members(config, key, "skill name → behaviour")) {
              const auto m = s.is_monitor.find(name);
              if (m == s.is_monitor.end()) config.child(key).fail(name, "not an announced skill or monitor");
              s.by_skill[name] = parse_behaviour(behaviour, m->second ? s.default_monitor : s.default_skill);
            }
          },
          "a skill's or monitor's own behaviour, over `default`"),
      own_setting<S>(
          "nodes", "object: node id → behaviour", "{}", "",
          [](const Config& config, const std::string& key, S& s) {
            for (const auto& [node_id, behaviour] : members(config, key, "node id → behaviour"))
              s.by_node[node_id] = parse_behaviour(behaviour, s.default_skill);
          },
          "a recipe node's own behaviour (`\"root/0/1\"`), over its skill's"),
      setting<S>("receipt_trace_path", "", &S::receipt_trace_path,
                 "stamp each command taken (whom it names, kind, task, node, the controller's stamp, when the "
                 "command handler began) and each event written (kind 100 + the event's: 100 SUCCESS, 101 "
                 "FAILURE, 102 STOPPED; stamped as it is written) and write them to this file when the executor "
                 "stops (task_controller_live_bench reads it); `\"\"`: off"),
  };
  return table;
}

}  // namespace rigger::scripted
