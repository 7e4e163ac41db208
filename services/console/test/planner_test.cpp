// The planner's logic without HTTP or DDS: the live skill library from announcements, validation by the
// controller's validator with canonical export, and the screw list matched to the world model's holes.
#include <cmath>
#include <fstream>
#include <sstream>

#include <gtest/gtest.h>

#include "planner.hpp"

namespace rigger::console {
namespace {

using nlohmann::json;

std::string read_file(const std::string& path) {
  std::ifstream in(std::string(RIGGER_SOURCE_DIR) + "/" + path);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

// The real library (generated from the executors' code), split over two executors as in the cell.
void announce_cell_library(SkillCatalog& catalog) {
  const json library = json::parse(read_file("recipes/examples/skill_library.json"));
  json skills = library, monitors = library;
  skills["skills"] = json::array();
  monitors["skills"] = json::array();
  for (const auto& d : library["skills"]) (d["kind"] == "monitor" ? monitors : skills)["skills"].push_back(d);
  catalog.update("robot-skills", true, skills.dump());
  catalog.update("monitors", true, monitors.dump());
}

TEST(SkillCatalog, MergesTheLiveExecutorsLibrariesAndForgetsDepartedOnes) {
  SkillCatalog catalog;
  announce_cell_library(catalog);
  EXPECT_NE(catalog.library().find("Screw"), nullptr);
  EXPECT_NE(catalog.library().find("YankMonitor"), nullptr);
  // The controller's own conditions are there without an executor announcing them.
  EXPECT_NE(catalog.library().find("ObjectLocalized"), nullptr);
  json described = catalog.to_json();
  EXPECT_EQ(described["executors"]["monitors"].size(), 3u);
  EXPECT_TRUE(described["problems"].empty()) << described["problems"];
  bool screw_has_units = false;
  for (const auto& s : described["skills"])
    if (s["name"] == "Screw")
      for (const auto& p : s["params"]) screw_has_units = screw_has_units || (p["name"] == "torque_nm" && p["unit"] == "Nm");
  EXPECT_TRUE(screw_has_units) << "the descriptions carry the parameters' units";

  catalog.update("monitors", false, "");
  EXPECT_EQ(catalog.library().find("YankMonitor"), nullptr);
  catalog.update("broken", true, "{not json");
  described = catalog.to_json();
  ASSERT_EQ(described["problems"].size(), 1u);
  EXPECT_NE(described["problems"][0].get<std::string>().find("broken"), std::string::npos);
}

TEST(PlannerValidation, TheControllersValidatorFindsTheErrorByPointer) {
  SkillCatalog catalog;
  announce_cell_library(catalog);
  json recipe = {{"recipe_version", 1},
                 {"task_id", "planned"},
                 {"root",
                  {{"type", "Sequence"},
                   {"children",
                    {{{"type", "Skill"}, {"skill", "Localize"}, {"params", {{"object", "target"}}}},
                     {{"type", "Parallel"},
                      {"success_threshold", 2},
                      {"failure_threshold", 1},
                      {"children",
                       {{{"type", "Skill"}, {"skill", "Localize"}, {"params", {{"object", "load"}}}},
                        {{"type", "Monitor"}, {"monitor", "YankMonitor"}, {"params", {{"max_yank_n_per_s", 2000}}}}}}}}}}}};
  json r = validate_recipe(catalog.library(), recipe.dump());
  EXPECT_FALSE(r["ok"].get<bool>());
  bool threshold = false;
  for (const auto& e : r["errors"]) threshold = threshold || e["pointer"] == "/root/children/1/success_threshold";
  EXPECT_TRUE(threshold) << r["errors"].dump(2);
  // The canonical text is there for an invalid recipe too, keys sorted.
  const std::string canonical = r["canonical"];
  EXPECT_LT(canonical.find("\"recipe_version\""), canonical.find("\"root\""));
  EXPECT_LT(canonical.find("\"root\""), canonical.find("\"task_id\""));

  recipe["root"]["children"][1]["success_threshold"] = 1;
  r = validate_recipe(catalog.library(), recipe.dump());
  EXPECT_TRUE(r["ok"].get<bool>()) << r["errors"].dump(2);
  EXPECT_EQ(r["canonical"], canonical_json(recipe));
  EXPECT_EQ(json::parse(r["canonical"].get<std::string>()), recipe);
}

TEST(PlannerValidation, MalformedTextIsAnErrorWithItsPositionAndNoCanonicalText) {
  SkillCatalog catalog;
  announce_cell_library(catalog);
  const json r = validate_recipe(catalog.library(), "{\"task_id\": 5");
  EXPECT_FALSE(r["ok"].get<bool>());
  ASSERT_FALSE(r["errors"].empty());
  EXPECT_FALSE(r.contains("canonical"));
  const json empty = validate_recipe(catalog.library(), "");
  EXPECT_FALSE(empty["ok"].get<bool>());
  // The shipped recipe validates against the cell's library, as the controller would say.
  EXPECT_TRUE(validate_recipe(catalog.library(), read_file("recipes/crane_insert.json"))["ok"].get<bool>());
}

TEST(PlannerScrews, BadRequestsNameTheField) {
  const auto refused = [](const json& body) -> PlannerError {
    try {
      parse_screw_request(body);
    } catch (const PlannerError& e) {
      return e;
    }
    ADD_FAILURE() << "accepted " << body.dump();
    return {};
  };
  EXPECT_EQ(refused(json::object()).pointer, "/model");
  EXPECT_EQ(refused({{"model", "/tmp/x.step"}, {"holes", {0}}}).pointer, "/model");
  EXPECT_EQ(refused({{"model", "object:"}, {"holes", {0}}}).pointer, "/model");
  EXPECT_EQ(refused({{"model", "object:target"}}).pointer, "/holes");
  EXPECT_EQ(refused({{"model", "object:target"}, {"holes", json::array()}}).pointer, "/holes");
  EXPECT_EQ(refused({{"model", "object:target"}, {"holes", {0, "h1"}}}).pointer, "/holes/1");
  EXPECT_EQ(refused({{"model", "object:target"}, {"holes", {-1}}}).pointer, "/holes/0");
  const ScrewRequest ok = parse_screw_request({{"model", "object:target"}, {"holes", {3, {{"kind", "face"}, {"index", 6}}}}});
  EXPECT_EQ(ok.entity, "target");
  EXPECT_EQ(ok.holes.size(), 2u);
}

TEST(PlannerScrews, EachDerivedHoleIsTheWorldModelsScrewHoleAtItsEntry) {
  const ScrewRequest request = parse_screw_request({{"model", "object:target"}, {"holes", {1, 0}}});
  const json cad = {{"parameter", "screw_list"},
                    {"screws",
                     {{{"hole", 1}, {"pose", {{"position_m", {0.15, -0.1, 0.0}}}}},
                      {{"hole", 0}, {"pose", {{"position_m", {-0.15, -0.1, 0.0}}}}}}}};
  const json entity = {{"id", "target"},
                       {"features",
                        {{"screw_holes",
                          {{{"id", "h1"}, {"pose", {{"position_m", {-0.15, -0.1, 0.0}}}}, {"screw_type", "M12x40"}, {"torque_nm", 60}},
                           {{"id", "h2"}, {"pose", {{"position_m", {0.1502, -0.1, 0.0}}}}, {"screw_type", "M12x50"}, {"torque_nm", 70}}}}}}};
  const json out = screws_with_features(request, "abc", cad, entity);
  EXPECT_EQ(out["model_sha256"], "abc");
  ASSERT_EQ(out["screws"].size(), 2u);
  EXPECT_EQ(out["screws"][0]["feature"], "target/h2");  // 0.2 mm away: within 1 mm
  EXPECT_EQ(out["screws"][0]["screw_type"], "M12x50");
  EXPECT_EQ(out["screws"][0]["torque_nm"], 70);
  EXPECT_EQ(out["screws"][0]["pose"], cad["screws"][0]["pose"]) << "positions are the CAD service's, untouched";
  EXPECT_EQ(out["screws"][1]["feature"], "target/h1");

  // A hole the world model does not know: refused, naming the hole and the nearest feature.
  json moved = cad;
  moved["screws"][1]["pose"]["position_m"] = {-0.15, -0.05, 0.0};
  try {
    screws_with_features(request, "abc", moved, entity);
    ADD_FAILURE() << "a hole without a screw-hole feature was accepted";
  } catch (const PlannerError& e) {
    EXPECT_EQ(e.pointer, "/holes/1");
    EXPECT_NE(e.message.find("nearest: h1 at 50"), std::string::npos) << e.message;
  }
  try {
    screws_with_features(request, "abc", cad, json{{"id", "target"}});
    ADD_FAILURE() << "an entity without screw holes was accepted";
  } catch (const PlannerError& e) {
    EXPECT_NE(e.message.find("it has none"), std::string::npos) << e.message;
  }
}

TEST(PlannerFrames, BadRequestsNameTheField) {
  const auto refused = [](const json& body) -> PlannerError {
    try {
      parse_frame_request(body);
    } catch (const PlannerError& e) {
      return e;
    }
    ADD_FAILURE() << "accepted " << body.dump();
    return {};
  };
  const json pt = {0.01, 0.02, 0.03};
  EXPECT_EQ(refused({{"rule", "hole"}, {"hole", 0}}).pointer, "/model");
  EXPECT_EQ(refused({{"model", "object:target"}}).pointer, "/rule");
  EXPECT_EQ(refused({{"model", "object:target"}, {"rule", "sphere"}}).pointer, "/rule");
  EXPECT_EQ(refused({{"model", "object:target"}, {"rule", "edges"}, {"point_m", pt}, {"edges", {4}}}).pointer, "/edges");
  EXPECT_EQ(refused({{"model", "object:target"}, {"rule", "edges"}, {"point_m", pt}, {"edges", {4, "e7"}}}).pointer,
            "/edges/1");
  EXPECT_EQ(refused({{"model", "object:target"}, {"rule", "edges"}, {"point_m", {1, 2}}, {"edges", {4, 7}}}).pointer,
            "/point_m");
  EXPECT_EQ(refused({{"model", "object:target"}, {"rule", "face"}, {"point_m", pt}}).pointer, "/face");
  EXPECT_EQ(refused({{"model", "object:target"}, {"rule", "hole"}, {"hole", -1}}).pointer, "/hole");
  // Only the rule's own fields go to the CAD service.
  const FrameRequest ok = parse_frame_request(
      {{"model", "object:load"}, {"rule", "face"}, {"face", {{"kind", "face"}, {"index", 5}}}, {"point_m", pt}, {"hole", 2}});
  EXPECT_EQ(ok.entity, "load");
  EXPECT_EQ(ok.args, json({{"rule", "face"}, {"face", {{"kind", "face"}, {"index", 5}}}, {"point_m", pt}}));
}

TEST(PlannerFrames, ACadFrameBecomesAPoseInThePartsFrameWithTheCellsRollPitchYaw) {
  const auto pose = [](const json& rotation) {
    return pose_from_cad_frame({{"frame", {{"position_m", {0.1, -0.2, 0.3}}, {"rotation", rotation}}}}, "target");
  };
  const json identity = pose({{1, 0, 0}, {0, 1, 0}, {0, 0, 1}});
  EXPECT_EQ(identity, json({{"position_m", {0.1, -0.2, 0.3}}, {"rpy_deg", {0.0, 0.0, 0.0}}, {"frame", "target"}}));
  // Rz(90°) Rx(180°): x → y, y → x, z → -z (a tool pointing down into a face, turned a quarter).
  const json turned = pose({{0, 1, 0}, {1, 0, 0}, {0, 0, -1}});
  EXPECT_NEAR(std::abs(turned["rpy_deg"][0].get<double>()), 180.0, 1e-6);
  EXPECT_NEAR(turned["rpy_deg"][1].get<double>(), 0.0, 1e-6);
  EXPECT_NEAR(turned["rpy_deg"][2].get<double>(), 90.0, 1e-6);
  // Pitch 90° (x along -z): gimbal lock, roll is 0 and the yaw carries the rest.
  const json down = pose({{0, 0, 1}, {0, 1, 0}, {-1, 0, 0}});
  EXPECT_NEAR(down["rpy_deg"][1].get<double>(), 90.0, 1e-6);
  EXPECT_EQ(down["rpy_deg"][0].get<double>(), 0.0);
  EXPECT_NEAR(down["rpy_deg"][2].get<double>(), 0.0, 1e-6);
  EXPECT_THROW(pose_from_cad_frame({{"rule", "hole"}}, "target"), PlannerError);
  EXPECT_THROW(pose({{1, 0, 0}, {0, 1, 0}}), PlannerError);
}

}  // namespace
}  // namespace rigger::console
