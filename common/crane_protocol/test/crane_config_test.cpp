#include "rigger/crane_protocol/crane_config.hpp"

#include <gtest/gtest.h>

#include <cstdio>
#include <fstream>
#include <functional>
#include <nlohmann/json.hpp>
#include <string>

namespace rigger::crane {
namespace {

nlohmann::json attributes() {
  return nlohmann::json::parse(R"({
    "rail_height_m": 4.5,
    "bridge_range_m": [0.0, 8.0], "trolley_range_m": [0.5, 5.0], "rope_length_range_m": [0.5, 3.8],
    "max_speed_mps": [0.5, 0.4, 0.2], "max_accel_mps2": [0.5, 0.3, 0.25],
    "rated_load_kg": 3200 })");
}

std::string expect_error(const nlohmann::json& attrs) {
  try {
    crane_limits_from_attributes(attrs, "/entities/1/attributes");
  } catch (const CraneConfigError& e) {
    return e.what();
  }
  ADD_FAILURE() << "no CraneConfigError";
  return {};
}

TEST(CraneConfig, MapsRangesAndHookHeight) {
  const CraneLimits limits = crane_limits_from_attributes(attributes(), "/x");
  EXPECT_DOUBLE_EQ(limits.position_min_m.x(), 0.0);
  EXPECT_DOUBLE_EQ(limits.position_max_m.x(), 8.0);
  EXPECT_DOUBLE_EQ(limits.position_min_m.y(), 0.5);
  EXPECT_DOUBLE_EQ(limits.position_max_m.y(), 5.0);
  // Hook height = rail height - rope length: the longest rope gives the lowest hook.
  EXPECT_DOUBLE_EQ(limits.position_min_m.z(), 4.5 - 3.8);
  EXPECT_DOUBLE_EQ(limits.position_max_m.z(), 4.5 - 0.5);
  EXPECT_DOUBLE_EQ(limits.max_speed_mps.y(), 0.4);
  EXPECT_DOUBLE_EQ(limits.max_accel_mps2.z(), 0.25);
  EXPECT_DOUBLE_EQ(limits.rated_load_kg, 3200.0);
}

TEST(CraneConfig, ErrorsNameThePointer) {
  auto attrs = attributes();
  attrs.erase("rated_load_kg");
  EXPECT_NE(expect_error(attrs).find("/entities/1/attributes/rated_load_kg: missing"),
            std::string::npos);

  attrs = attributes();
  attrs["max_speed_mps"] = {0.5, 0.5};
  EXPECT_NE(
      expect_error(attrs).find("/entities/1/attributes/max_speed_mps: expected an array of 3"),
      std::string::npos);

  attrs = attributes();
  attrs["bridge_range_m"][1] = "far";
  EXPECT_NE(expect_error(attrs).find("/entities/1/attributes/bridge_range_m/1: expected a number"),
            std::string::npos);

  attrs = attributes();
  attrs["trolley_range_m"] = {5.0, 0.5};
  EXPECT_NE(expect_error(attrs).find("trolley range: minimum must be below maximum"),
            std::string::npos);

  attrs = attributes();
  attrs["max_accel_mps2"][0] = 0.0;
  EXPECT_NE(expect_error(attrs).find("bridge max acceleration"), std::string::npos);

  EXPECT_NE(expect_error(nlohmann::json::array()).find("bridge_range_m: missing"),
            std::string::npos);
}

TEST(CraneConfig, LoadsTheShippedCell) {
  const std::string path = std::string(RIGGER_SOURCE_DIR) + "/deploy/cell/simulated_cell.json";
  std::ifstream in(path);
  const auto cell = nlohmann::json::parse(in);
  nlohmann::json crane;
  for (const auto& entity : cell["entities"]) {
    if (entity["id"] == "crane") crane = entity["attributes"];
  }
  ASSERT_TRUE(crane.is_object());
  const CraneLimits limits = load_crane_limits(path);
  EXPECT_DOUBLE_EQ(limits.position_max_m.x(), crane["bridge_range_m"][1].get<double>());
  EXPECT_DOUBLE_EQ(limits.position_min_m.z(), crane["rail_height_m"].get<double>() -
                                                  crane["rope_length_range_m"][1].get<double>());
  EXPECT_DOUBLE_EQ(limits.rated_load_kg, crane["rated_load_kg"].get<double>());
}

// The shipped cell with one change made by `edit` to its crane entity, written to a temporary file.
std::string shipped_cell_with(const std::function<void(nlohmann::json& crane)>& edit) {
  std::ifstream in(std::string(RIGGER_SOURCE_DIR) + "/deploy/cell/simulated_cell.json");
  auto cell = nlohmann::json::parse(in);
  for (auto& entity : cell["entities"]) {
    if (entity["id"] == "crane") edit(entity);
  }
  const std::string path = ::testing::TempDir() + "crane_config_test_cell.json";
  std::ofstream(path) << cell.dump(2);
  return path;
}

std::string load_error(const std::string& path) {
  try {
    load_crane_limits(path);
  } catch (const CraneConfigError& e) {
    return e.what();
  }
  ADD_FAILURE() << "no error for " << path;
  return {};
}

TEST(CraneConfig, FileErrorsNameTheFileAndWhere) {
  EXPECT_NE(load_error("/nonexistent/cell.json").find("/nonexistent/cell.json"), std::string::npos);

  std::string path = shipped_cell_with([](nlohmann::json& crane) { crane["id"] = "hoist"; });
  EXPECT_NE(load_error(path).find("no entity with id \"crane\""), std::string::npos);

  path = shipped_cell_with([](nlohmann::json& crane) { crane.erase("attributes"); });
  const std::string missing = load_error(path);
  EXPECT_NE(missing.find(path + ": /entities/"), std::string::npos) << missing;
  EXPECT_NE(missing.find("/attributes/bridge_range_m: missing"), std::string::npos) << missing;

  // Not a cell file at all: the cell reader's own error, with line and column.
  std::ofstream(path) << "{ not json";
  const std::string malformed = load_error(path);
  EXPECT_NE(malformed.find("expected valid JSON"), std::string::npos) << malformed;
  EXPECT_NE(malformed.find("line 1, column "), std::string::npos) << malformed;
  std::remove(path.c_str());
}

}  // namespace
}  // namespace rigger::crane
