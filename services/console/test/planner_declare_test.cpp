// Declaring a feature by picks: the rule built from the CAD service's references (a fake of its
// CAD_FEATURES answer) and the cell document with the feature added; refusals name the field.
#include <gtest/gtest.h>

#include "planner_declare.hpp"

namespace rigger::console {
namespace {

using nlohmann::json;

json sig(const char* type, json centroid, json direction, double radius = 0) {
  return {{"type", type}, {"centroid_m", centroid}, {"direction", direction}, {"radius_m", radius}};
}

// A plate: face 0 its top (z up), face 1 a side; edge 0 along x in the top, edge 1 vertical; holes 0..2
// on the top (0 and 1 of 10.2 mm, 2 of 6 mm only when `mixed`), hole 3 from the side.
json plate(bool mixed = false) {
  json faces = {{{"index", 0}, {"signature", sig("plane", {0, 0, 0.02}, {0, 0, 1})}, {"normal", {0, 0, 1}}},
                {{"index", 1}, {"signature", sig("plane", {0.2, 0, 0}, {1, 0, 0})}, {"normal", {1, 0, 0}}}};
  json holes = json::array();
  const double d[4] = {0.0102, 0.0102, mixed ? 0.006 : 0.0102, 0.0102};
  const json entry[4] = {{-0.1, -0.1, 0.02}, {0.1, -0.1, 0.02}, {0.1, 0.1, 0.02}, {0.2, 0, 0}};
  const json axis[4] = {{0, 0, 1}, {0, 0, 1}, {0, 0, 1}, {1, 0, 0}};
  for (int i = 0; i < 4; ++i) {
    faces.push_back({{"index", 2 + i}, {"signature", sig("cylinder", entry[i], axis[i], d[i] / 2)}});
    holes.push_back({{"index", i}, {"faces", {2 + i}}, {"axis", axis[i]}, {"entry_m", entry[i]}, {"diameter_m", d[i]},
                     {"depth_m", 0.03}, {"through", false}});
  }
  json edges = {{{"index", 0}, {"signature", sig("line", {0, -0.15, 0.02}, {1, 0, 0})}},
                {{"index", 1}, {"signature", sig("line", {0.2, -0.15, 0}, {0, 0, 1})}}};
  return {{"faces", faces}, {"edges", edges}, {"holes", holes}};
}

json cell() {
  return {{"cell_version", 1},
          {"entities", {{{"id", "target"}, {"model", {{"static", true}}}, {"features", {{"screw_holes", {{{"id", "h1"}}}}}}}}}};
}

json declare(const json& body, bool mixed = false) {
  return declare_feature(parse_declare_request(body), cell(), plate(mixed));
}

std::string refusal(const json& body, bool mixed = false) {
  try {
    declare(body, mixed);
  } catch (const PlannerError& e) {
    return e.pointer + ": " + e.message;
  }
  return "accepted";
}

TEST(PlannerDeclare, GraspFrameIsAFaceRuleWithTheCadReferences) {
  const json out = declare({{"model", "object:target"}, {"kind", "grasp_frame"}, {"name", "grasp_top"},
                            {"face", 0}, {"x_edge", 0}, {"x_reversed", true}});
  const json& frames = out["cell"]["entities"][0]["features"]["grasp_frames"];
  ASSERT_EQ(frames.size(), 1u);
  EXPECT_EQ(frames[0]["id"], "grasp_top");
  const json& rule = frames[0]["cad"];
  EXPECT_EQ(rule["rule"], "face");
  EXPECT_EQ(rule["z"], "into");
  EXPECT_EQ(rule["face"], json({{"kind", "face"}, {"index", 0}, {"signature", sig("plane", {0, 0, 0.02}, {0, 0, 1})}}));
  EXPECT_EQ(rule["x_edge"]["kind"], "edge");
  EXPECT_EQ(rule["x_edge"]["signature"]["direction"], json({1, 0, 0}));
  EXPECT_EQ(rule["x_reversed"], true);
  EXPECT_FALSE(rule.contains("standoff_m"));
  EXPECT_EQ(out["features"], json({"target/grasp_top"}));
  // The features already there stay.
  EXPECT_EQ(out["cell"]["entities"][0]["features"]["screw_holes"].size(), 1u);
}

TEST(PlannerDeclare, ApproachWaypointCarriesTheStandoff) {
  const json out = declare({{"model", "object:target"}, {"kind", "approach_waypoint"}, {"name", "pre"}, {"face", 1},
                            {"standoff_m", 0.1}});
  const json& rule = out["cell"]["entities"][0]["features"]["approach_waypoints"][0]["cad"];
  EXPECT_EQ(rule["standoff_m"], 0.1);
  EXPECT_EQ(rule["face"]["index"], 1);
  EXPECT_FALSE(rule.contains("x_edge"));
  EXPECT_EQ(refusal({{"model", "object:target"}, {"kind", "approach_waypoint"}, {"name", "pre"}, {"face", 1}}).substr(0, 12),
            "/standoff_m:");
}

TEST(PlannerDeclare, AllHolesLikeThisOneAreTheSameDiameterAndAxisOnTheSameFace) {
  const json out = declare({{"model", "object:target"}, {"kind", "screw_holes"}, {"name", "m"}, {"hole", 1}, {"like", true},
                            {"screw", {{"screw_type", "M10x30"}, {"torque_nm", 45}}}});
  const json& holes = out["cell"]["entities"][0]["features"]["screw_holes"];
  ASSERT_EQ(holes.size(), 4u);  // h1 and the three on the top; not the side's hole 3
  EXPECT_EQ(out["features"], json({"target/m1", "target/m2", "target/m3"}));
  EXPECT_EQ(holes[1]["cad"]["hole"]["index"], 3);  // the picked hole first: its face 3
  EXPECT_EQ(holes[2]["cad"]["hole"]["index"], 2);
  EXPECT_EQ(holes[3]["cad"]["hole"]["index"], 4);
  EXPECT_EQ(holes[3]["cad"]["hole"]["signature"]["type"], "cylinder");
  EXPECT_EQ(holes[2]["screw_type"], "M10x30");
  EXPECT_EQ(holes[2]["torque_nm"], 45);
  // One screw per hole from the table.
  const json table = declare({{"model", "object:target"}, {"kind", "screw_holes"}, {"name", "s"}, {"hole", 3},
                              {"screw", {{"screw_type", "M10x30"}, {"torque_nm", 45}}},
                              {"screws", {{{"screw_type", "M12x40"}, {"torque_nm", 60}}}}});
  EXPECT_EQ(table["rule"][0]["screw_type"], "M12x40");
}

// A face with holes of two diameters holds two patterns: "like" the picked 10.2 mm hole takes the other
// 10.2 mm one and leaves the 6 mm hole, which "like" of its own picks alone.
TEST(PlannerDeclare, AllHolesLikeThisOneLeaveTheHolesOfAnotherDiameter) {
  const json like = {{"model", "object:target"}, {"kind", "screw_holes"}, {"name", "m"}, {"hole", 0}, {"like", true},
                     {"screw", {{"screw_type", "M10x30"}, {"torque_nm", 45}}}};
  const json wide = declare(like, true);
  EXPECT_EQ(wide["features"], json({"target/m1", "target/m2"}));
  EXPECT_EQ(wide["rule"][1]["cad"]["hole"]["index"], 3);  // hole 1's face
  json narrow_pick = like;
  narrow_pick["hole"] = 2;
  narrow_pick["name"] = "n";
  narrow_pick["screw"] = {{"screw_type", "M6x20"}, {"torque_nm", 10}};
  const json narrow = declare(narrow_pick, true);
  EXPECT_EQ(narrow["features"], json({"target/n1"}));
  EXPECT_EQ(narrow["rule"][0]["torque_nm"], 10);
}

TEST(PlannerDeclare, BadPicksAreRefusedAtTheirField) {
  const json base = {{"model", "object:target"}, {"kind", "grasp_frame"}, {"name", "g"}};
  json b = base;
  b["face"] = 0;
  b["x_edge"] = 1;  // vertical: along the top face's normal
  EXPECT_NE(refusal(b).find("/x_edge: edge 1 does not lie in face 0's plane"), std::string::npos) << refusal(b);
  b = base;
  b["face"] = 2;  // a hole's cylinder
  EXPECT_NE(refusal(b).find("is a cylinder, not a plane"), std::string::npos) << refusal(b);
  b["face"] = 40;
  EXPECT_NE(refusal(b).find("/face: object:target has 6 faces, no face 40"), std::string::npos) << refusal(b);
  const json holes = {{"model", "object:target"}, {"kind", "screw_holes"}, {"name", "m"}, {"hole", 0}, {"like", true},
                      {"screw", {{"screw_type", "M10x30"}, {"torque_nm", 45}}}};
  json taken = holes;
  taken["name"] = "h";  // h1 is there
  EXPECT_EQ(refusal(taken), "/name: \"target\" already has a feature \"h1\": pick another name");
  json screws = holes;
  screws["screws"] = json::array({{{"screw_type", "M10x30"}, {"torque_nm", 45}}});
  EXPECT_NE(refusal(screws).find("/screws: expected one screw per hole (3)"), std::string::npos) << refusal(screws);
  EXPECT_EQ(refusal({{"model", "object:crane"}, {"kind", "grasp_frame"}, {"name", "g"}, {"face", 0}}),
            "/model: the running cell revision has no entity \"crane\"");
  EXPECT_EQ(refusal({{"model", "object:target"}, {"kind", "pin"}, {"name", "g"}}).substr(0, 6), "/kind:");
  EXPECT_EQ(refusal({{"model", "object:target"}, {"kind", "grasp_frame"}, {"name", "a b"}}).substr(0, 6), "/name:");
}

}  // namespace
}  // namespace rigger::console

namespace rigger::console {
namespace {

// The load's bottom face (face 0 of this fake, a plane) on the target's top face (face 0 of the plate).
json load_features() {
  return {{"faces", {{{"index", 0}, {"signature", sig("plane", {0, 0, -0.1}, {0, 0, -1})}, {"normal", {0, 0, -1}}},
                     {{"index", 1}, {"signature", sig("cylinder", {0, 0, 0}, {0, 0, 1}, 0.01)}}}},
          {"edges", json::array()},
          {"holes", json::array()}};
}

json cell_with_load() {
  json c = cell();
  c["entities"].push_back({{"id", "load"}});
  return c;
}

TEST(PlannerDeclare, AnInsertionMatesAPickedFaceOfThePartOnAPickedFaceOfTheTarget) {
  const json body = {{"model", "object:load"}, {"kind", "insertion"}, {"face", 0},
                     {"target", {{"model", "object:target"}, {"face", 0}}}};
  const json out = declare_feature(parse_declare_request(body), cell_with_load(), load_features(), plate());
  const json& insertion = out.at("cell").at("entities").at(1).at("features").at("insertion");
  EXPECT_EQ(insertion.at("target"), "target");
  EXPECT_EQ(insertion.at("cad").at("rule"), "mate_faces");
  EXPECT_EQ(insertion.at("cad").at("face").at("signature").at("direction"), json({0, 0, -1}));
  EXPECT_EQ(insertion.at("cad").at("target_face").at("index"), 0);
  EXPECT_EQ(out.at("features"), json({"load/insertion"}));

  // One insertion per part; a face that is no plane; the part into itself; no target.
  EXPECT_THROW(declare_feature(parse_declare_request(body), out.at("cell"), load_features(), plate()), PlannerError);
  json cylinder = body;
  cylinder["face"] = 1;
  try {
    declare_feature(parse_declare_request(cylinder), cell_with_load(), load_features(), plate());
    ADD_FAILURE() << "a cylinder mated";
  } catch (const PlannerError& e) {
    EXPECT_EQ(e.pointer, "/face");
    EXPECT_NE(e.message.find("not a plane"), std::string::npos) << e.message;
  }
  json itself = body;
  itself["target"]["model"] = "object:load";
  EXPECT_EQ(refusal(itself).substr(0, 14), "/target/model:");
  json none = body;
  none.erase("target");
  EXPECT_EQ(refusal(none).substr(0, 14), "/target/model:");
  // Into a loose part: refused here, not first by the physics at a rehearsal.
  json loose = cell_with_load();
  loose["entities"][0]["model"]["static"] = false;
  try {
    declare_feature(parse_declare_request(body), loose, load_features(), plate());
    ADD_FAILURE() << "an insertion into a loose part was declared";
  } catch (const PlannerError& e) {
    EXPECT_EQ(e.pointer, "/target/model");
    EXPECT_NE(e.message.find("\"target\" is loose"), std::string::npos) << e.message;
  }
}

TEST(PlannerDeclare, AnInsertionPinnedByAHoleOfEachPartNamesTheHolesFaces) {
  // Both parts are plates here: the load's hole 0 on the target's hole 1, its hole 1 on the target's 0.
  json body = {{"model", "object:load"}, {"kind", "insertion"}, {"face", 0},
               {"target", {{"model", "object:target"}, {"face", 0}}},
               {"pins", {{{"hole", 0}, {"target_hole", 1}}, {{"hole", 1}, {"target_hole", 0}}}}};
  const json out = declare_feature(parse_declare_request(body), cell_with_load(), plate(), plate());
  const json& pins = out.at("cell").at("entities").at(1).at("features").at("insertion").at("cad").at("pins");
  ASSERT_EQ(pins.size(), 2u);
  EXPECT_EQ(pins[0].at("hole").at("index"), 2);  // hole 0's cylinder is face 2
  EXPECT_EQ(pins[0].at("target_hole").at("index"), 3);
  EXPECT_EQ(pins[0].at("target_hole").at("signature").at("type"), "cylinder");
  EXPECT_EQ(pins[1].at("hole").at("index"), 3);

  const auto refused = [&](const json& request) {
    try {
      declare_feature(parse_declare_request(request), cell_with_load(), plate(), plate());
    } catch (const PlannerError& e) {
      return e.pointer + ": " + e.message;
    }
    return std::string("accepted");
  };
  json unknown = body;
  unknown["pins"][1]["target_hole"] = 9;
  EXPECT_EQ(refused(unknown), "/pins/1/target_hole: object:target has 4 holes, no hole 9");
  json three = body;
  three["pins"].push_back(body["pins"][0]);
  EXPECT_EQ(refused(three).substr(0, 7), "/pins: ");
  json half = body;
  half["pins"][0].erase("target_hole");
  EXPECT_EQ(refused(half).substr(0, 9), "/pins/0: ");
}

}  // namespace
}  // namespace rigger::console
