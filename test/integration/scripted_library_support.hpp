#pragma once
// A cell without devices, for the console's browser tests: two scripted executors announcing the real
// skill library (recipes/examples/skill_library.json), "skills" (each succeeds after 0.2 s) and "monitors"
// (each runs until it is shut down), their configurations written to the cell's log folder.
#include <fstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "cell_sim_test_support.hpp"

namespace rigger::testing {

/// Starts the scripted executors "skills" (offering `skills`) and "monitors" (TimerMonitor, ForceMonitor,
/// YankMonitor) in `cell`; the caller waits for them to be READY.
inline void start_scripted_library_executors(Cell& cell, const std::vector<std::string>& skills) {
  const std::string library = repo_file("recipes/examples/skill_library.json");
  const auto start = [&](const std::string& id, const nlohmann::json& config) {
    const std::string path = cell.log_dir() + "/" + id + ".json";
    std::ofstream(path) << config.dump(2);
    cell.start(id, "scripted_executor", {"--id", id, "--config", path});
  };
  start("skills",
        {{"library_file", library}, {"skills", skills}, {"default", {{"mode", "succeed"}, {"delay_s", 0.2}}}});
  start("monitors", {{"library_file", library},
                     {"skills", {"TimerMonitor", "ForceMonitor", "YankMonitor"}},
                     {"default", {{"mode", "run"}}}});
}

}  // namespace rigger::testing
