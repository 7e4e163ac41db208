#pragma once
// Shared by the integration tests that show the calibration board to the camera (calibration_board_test.cpp,
// calibrate_camera_test.cpp): the demo cell with test/data's board on its robot, and the services' configurations
// on it.
#include <filesystem>
#include <fstream>
#include <functional>
#include <string>

#include <nlohmann/json.hpp>

#include "cell_sim_test_support.hpp"

namespace rigger::testing {

/// The demo cell with the board on its robot, `edit` applied to the document after, in `log_dir`/cell beside a
/// copy of its STEP models; its path.
inline std::string write_board_cell(const std::string& log_dir,
                                    const std::function<void(nlohmann::json&)>& edit = nullptr) {
  const std::filesystem::path dir = std::filesystem::path(log_dir) / "cell";
  std::filesystem::create_directories(dir);
  std::filesystem::copy(repo_file("deploy/cell/models"), dir / "models", std::filesystem::copy_options::recursive);
  std::ifstream in(repo_file("deploy/cell/simulated_cell.json"));
  nlohmann::json cell = nlohmann::json::parse(in);
  std::ifstream board(repo_file("test/data/calibration_board.json"));
  for (nlohmann::json& entity : cell["entities"])
    if (entity["id"] == "robot") entity["calibration_board"] = nlohmann::json::parse(board);
  if (edit) edit(cell);
  const std::string path = (dir / "simulated_cell.json").string();
  std::ofstream(path) << cell.dump(2);
  return path;
}

/// deploy/config/<name>.json on `cell_file` (its key cell_file or cell_config, when it has one) with `patch`
/// merged in, in `log_dir`; its path.
inline std::string config_on(const std::string& log_dir, const std::string& name, const std::string& cell_file,
                             const nlohmann::json& patch = nlohmann::json::object()) {
  std::ifstream in(repo_file("deploy/config/" + name + ".json"));
  nlohmann::json c = nlohmann::json::parse(in);
  for (const char* key : {"cell_file", "cell_config"})
    if (c.contains(key)) c[key] = cell_file;
  c.merge_patch(patch);
  const std::string path = log_dir + "/" + name + ".json";
  std::ofstream(path) << c.dump(2);
  return path;
}

}  // namespace rigger::testing
