#include "rigger/crane_protocol/crane_config.hpp"

#include <gtest/gtest.h>

#include <cstdio>
#include <fstream>
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

TEST(CraneConfig, FileErrors) {
  EXPECT_THROW(load_crane_limits("/nonexistent/cell.json"), CraneConfigError);
  const std::string path = ::testing::TempDir() + "crane_config_test_bad.json";
  {
    std::ofstream out(path);
    out << R"({"entities": [ {"id": 7}, {"id": "robot"} ]})";
  }
  try {
    load_crane_limits(path);
    ADD_FAILURE() << "no error";
  } catch (const CraneConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("no entity with id \"crane\""), std::string::npos);
  }
  {
    std::ofstream out(path);
    out << R"({"entities": [ {"id": "crane"} ]})";
  }
  try {
    load_crane_limits(path);
    ADD_FAILURE() << "no error";
  } catch (const CraneConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("/entities/0/attributes: missing"), std::string::npos);
  }
  {
    std::ofstream out(path);
    out << "{ not json";
  }
  EXPECT_THROW(load_crane_limits(path), CraneConfigError);
  std::remove(path.c_str());
}

}  // namespace
}  // namespace rigger::crane
