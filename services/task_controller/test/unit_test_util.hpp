#pragma once
// Shared by the controller's unit tests: skill-library documents cut from the scripted library.

#include <fstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

namespace rigger::task_controller::testing {

/// test/data/scripted_skill_library.json (what the scripted executor announces) with only `names`.
inline nlohmann::json library_with(const std::vector<std::string>& names) {
  std::ifstream in(std::string(RIGGER_SOURCE_DIR) + "/test/data/scripted_skill_library.json");
  const nlohmann::json all = nlohmann::json::parse(in);
  nlohmann::json out = all;
  out["skills"] = nlohmann::json::array();
  for (const auto& s : all.at("skills"))
    for (const auto& n : names)
      if (s.at("name") == n) out["skills"].push_back(s);
  return out;
}

}  // namespace rigger::task_controller::testing
