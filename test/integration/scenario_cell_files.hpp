#pragma once
// Which cell the scenario runs on, and the services' configurations that point at it: the shipped cell
// (deploy/cell/simulated_cell.json) unless a test brings its own cell file and names its load and target.
#include <fstream>
#include <map>
#include <stdexcept>
#include <string>

#include <Eigen/Geometry>
#include <nlohmann/json.hpp>

#include "rigger/cell_config/cell_cad.hpp"
#include "rigger/testing/cell.hpp"

namespace rigger::testing::scenario {

/// The cell a ScenarioCell starts the services on.
struct ScenarioSetup {
  std::string cell_file;             ///< absolute path; empty: the shipped deploy/cell/simulated_cell.json
  std::string load_id = "load";      ///< the object the crane carries and the robot inserts
  std::string target_id = "target";  ///< the object the load is inserted on
  /// Per service configuration name (e.g. "cell_sim" for its camera's renderer and pose_error): merged into
  /// its shipped configuration last.
  std::map<std::string, nlohmann::json> patches = {};
};

/// The absolute path of the setup's cell file.
inline std::string cell_file_of(const ScenarioSetup& setup) {
  return setup.cell_file.empty() ? repo_file("deploy/cell/simulated_cell.json") : setup.cell_file;
}

/// deploy/config/<name>.json with `patch` merged in, written to `dir`; its path. The service's cell file
/// (key `cell_file` or `cell_config`) is the setup's; other relative paths in the shipped file are relative to the
/// repository root or to deploy/config, and the copies use absolute ones.
inline std::string service_config(const std::string& dir, const ScenarioSetup& setup, const std::string& name,
                                  const nlohmann::json& patch = nlohmann::json::object()) {
  std::ifstream in(repo_file("deploy/config/" + name + ".json"));
  nlohmann::json c = nlohmann::json::parse(in);
  for (const char* key : {"cell_file", "cell_config"}) {
    if (!c.contains(key)) continue;
    if (!setup.cell_file.empty()) {
      c[key] = setup.cell_file;
      continue;
    }
    std::string path = c[key].get<std::string>();
    if (path.rfind("../", 0) == 0) path = "deploy/config/" + path;
    c[key] = repo_file(path);
  }
  c.merge_patch(patch);
  const std::string path = dir + "/" + name + ".json";
  std::ofstream(path) << c.dump(2);
  return path;
}

/// The load's insertion pose in the target's frame as every process gets it: derived from the STEP models
/// (rigger_cell_cad). Throws std::runtime_error when the load has no insertion feature.
inline Eigen::Isometry3d insertion_offset(const ScenarioSetup& setup) {
  const cell::CellFile cell = cell::load_cell_file_with_cad(cell_file_of(setup));
  const auto& insertion = cell.require(setup.load_id, "the scenario's insertion error").features.insertion;
  if (!insertion) throw std::runtime_error("the cell file has no " + setup.load_id + " with an insertion feature");
  return insertion->pose_target_entity;
}

}  // namespace rigger::testing::scenario
