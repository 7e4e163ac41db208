// Placing an object by picks, without HTTP or DDS: a face on a face with normals opposite and a turn,
// the pose written in the object's own parent's frame, and the refusals.
#include <gtest/gtest.h>

#include "placement.hpp"
#include "rigger/cell_config/cell_types.hpp"

namespace rigger::console {
namespace {

using nlohmann::json;

Eigen::Isometry3d face(const Eigen::Vector3d& at, const Eigen::Matrix3d& r) {
  Eigen::Isometry3d f = Eigen::Isometry3d::Identity();
  f.linear() = r;
  f.translation() = at;
  return f;
}

/// A 0.2 m high part's bottom face frame (z out of the face: down, x the model's x) at the picked point.
Eigen::Isometry3d bottom_face(const Eigen::Vector3d& at) {
  return face(at, Eigen::AngleAxisd(M_PI, Eigen::Vector3d::UnitX()).toRotationMatrix());
}

json cell() {
  return json::parse(R"({"cell_version": 1, "entities": [
    {"id": "table", "kind": "object", "parent": "world", "pose": {"position_m": [2, 1, 0], "rpy_deg": [0, 0, 90]}},
    {"id": "part", "kind": "object", "parent": "world", "pose": {"position_m": [0, 0, 0], "rpy_deg": [0, 0, 0]}},
    {"id": "pin", "kind": "object", "parent": "part", "pose": {"position_m": [0, 0, 0.3], "rpy_deg": [0, 0, 0]}}]})");
}

Eigen::Isometry3d pose_in(const json& doc, const std::string& id) {
  const auto vector = [](const json& v) { return Eigen::Vector3d(v[0].get<double>(), v[1].get<double>(), v[2].get<double>()); };
  // The entity's pose in the world, through its parents.
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  for (std::string at = id; at != "world";) {
    for (const json& e : doc["entities"]) {
      if (e["id"] != at) continue;
      pose = cell::pose_from_position_rpy_deg(vector(e["pose"]["position_m"]), vector(e["pose"]["rpy_deg"])) * pose;
      at = e.value("parent", "world");
      break;
    }
  }
  return pose;
}

TEST(Placement, TheObjectsFaceLiesOnTheSupportsFaceAtThePickedPoints) {
  // The part's bottom face picked 3 cm off its centre, the table's top (0.75 m high) at (0.3, 0.2).
  const Eigen::Isometry3d own = bottom_face({0.03, 0.0, -0.1});
  const Eigen::Isometry3d onto = face({0.3, 0.2, 0.75}, Eigen::Matrix3d::Identity());
  const Eigen::Isometry3d p = placed_on(onto, own, 0.0);
  EXPECT_TRUE(p.linear().isApprox(Eigen::Matrix3d::Identity(), 1e-12));
  EXPECT_TRUE(p.translation().isApprox(Eigen::Vector3d(0.27, 0.2, 0.85), 1e-12)) << p.translation().transpose();
  // The picked points coincide and the normals are opposite.
  EXPECT_TRUE((p * own).translation().isApprox(onto.translation(), 1e-12));
  EXPECT_NEAR((p * own).linear().col(2).dot(onto.linear().col(2)), -1.0, 1e-12);
  // Turned a quarter about the support's normal.
  const Eigen::Isometry3d q = placed_on(onto, own, 90.0);
  EXPECT_TRUE((q * own).translation().isApprox(onto.translation(), 1e-12));
  EXPECT_NEAR((q.linear() * Eigen::Vector3d::UnitX()).dot(Eigen::Vector3d::UnitY()), 1.0, 1e-12);
}

TEST(Placement, TheNewPoseIsWrittenInTheObjectsParentFrame) {
  const Eigen::Isometry3d on_table = placed_on(face({0.3, 0.2, 0.75}, Eigen::Matrix3d::Identity()),
                                               bottom_face({0, 0, -0.1}), 0.0);
  const json placed = cell_with_placement(cell(), "part", "table", on_table);
  // The table stands at (2, 1) turned 90 degrees: its (0.3, 0.2) is the world's (1.8, 1.3).
  const Eigen::Isometry3d world_part = pose_in(placed, "part");
  EXPECT_TRUE(world_part.translation().isApprox(Eigen::Vector3d(1.8, 1.3, 0.85), 1e-9)) << world_part.translation().transpose();
  EXPECT_EQ(placed["entities"][1]["pose"]["rpy_deg"], json::array({0, 0, 90}));
  // What the part carries keeps its pose relative to it; the rest of the document is untouched.
  EXPECT_EQ(placed["entities"][2], cell()["entities"][2]);
  EXPECT_EQ(placed["entities"][0], cell()["entities"][0]);
  // Known here, or found by Localize at run time: the part's `localized` as asked, else as it was.
  EXPECT_FALSE(placed["entities"][1].contains("localized"));
  EXPECT_EQ(cell_with_placement(cell(), "part", "table", on_table, true)["entities"][1]["localized"], true);
  EXPECT_EQ(cell_with_placement(cell(), "part", "table", on_table, false)["entities"][1]["localized"], false);
  // The pin (parent: the part) placed on the table: written in the part's frame.
  const json pinned = cell_with_placement(cell(), "pin", "table", on_table);
  EXPECT_TRUE(pose_in(pinned, "pin").translation().isApprox(Eigen::Vector3d(1.8, 1.3, 0.85), 1e-9));
}

TEST(Placement, BadRequestsAreRefusedWithWhereAndWhat) {
  const auto refusal = [](const json& body) {
    try {
      parse_place_request(body);
    } catch (const PlannerError& e) {
      return e.pointer + ": " + e.message;
    }
    return std::string("accepted");
  };
  const json ok = {{"model", "object:part"}, {"face", 4}, {"point_m", {0, 0, -0.1}},
                   {"onto", {{"model", "object:table"}, {"face", 2}, {"point_m", {0, 0, 0.75}}}}};
  EXPECT_EQ(refusal(ok), "accepted");
  json b = ok;
  b.erase("onto");
  EXPECT_EQ(refusal(b).rfind("/onto: ", 0), 0u) << refusal(b);
  b = ok;
  b["onto"]["model"] = "object:part";
  EXPECT_EQ(refusal(b).rfind("/onto/model: ", 0), 0u) << refusal(b);
  b = ok;
  b["onto"].erase("point_m");
  EXPECT_EQ(refusal(b).rfind("/onto/point_m: ", 0), 0u) << refusal(b);
  b = ok;
  b["turn_deg"] = 1000;
  EXPECT_EQ(refusal(b).rfind("/turn_deg: ", 0), 0u) << refusal(b);
  b = ok;
  b["localized"] = "yes";
  EXPECT_EQ(refusal(b).rfind("/localized: ", 0), 0u) << refusal(b);
  b = ok;
  b["face"] = "top";
  EXPECT_EQ(refusal(b).rfind("/face: ", 0), 0u) << refusal(b);

  const Eigen::Isometry3d any = Eigen::Isometry3d::Identity();
  EXPECT_THROW(cell_with_placement(cell(), "ghost", "table", any), PlannerError);
  EXPECT_THROW(cell_with_placement(cell(), "part", "ghost", any), PlannerError);
  try {
    cell_with_placement(cell(), "part", "pin", any);  // the pin rides on the part
    ADD_FAILURE() << "placing the part on what it carries was accepted";
  } catch (const PlannerError& e) {
    EXPECT_EQ(e.pointer, "/onto/model");
    EXPECT_NE(e.message.find("carried by"), std::string::npos) << e.message;
  }
}

}  // namespace
}  // namespace rigger::console

namespace rigger::console {
namespace {

// Picked edges: the object turned so that its edge lies along the support's, for faces of any pose.
TEST(Placement, PickedEdgesLieAlongEachOtherOnceTheFacesMate) {
  const Eigen::Isometry3d onto_face =
      Eigen::Translation3d(0.3, -0.2, 0.9) * Eigen::AngleAxisd(0.4, Eigen::Vector3d(0.2, 1, 0.3).normalized());
  const Eigen::Isometry3d own_face =
      Eigen::Translation3d(0.05, 0.0, -0.1) * Eigen::AngleAxisd(2.0, Eigen::Vector3d(1, -0.4, 0.1).normalized());
  for (const double a_onto : {0.0, 0.7, 2.5}) {
    for (const double a_own : {0.0, 1.2, -2.0}) {
      const Eigen::Vector3d onto_edge = onto_face.linear() * Eigen::Vector3d(std::cos(a_onto), std::sin(a_onto), 0);
      const Eigen::Vector3d own_edge = own_face.linear() * Eigen::Vector3d(std::cos(a_own), std::sin(a_own), 0);
      const double turn = edge_turn_deg(onto_face, onto_edge, own_face, own_edge);
      const Eigen::Isometry3d placed = placed_on(onto_face, own_face, turn);
      EXPECT_NEAR((placed.linear() * own_edge).dot(onto_edge), 1.0, 1e-9) << a_onto << " " << a_own;
      // A further half turn lays it the other way along the same line.
      EXPECT_NEAR((placed_on(onto_face, own_face, turn + 180).linear() * own_edge).dot(onto_edge), -1.0, 1e-9);
    }
  }
  // An edge that leaves its face's plane is refused at its field.
  try {
    edge_turn_deg(onto_face, onto_face.linear().col(2), own_face, own_face.linear().col(0));
    ADD_FAILURE() << "an edge along the normal";
  } catch (const PlannerError& e) {
    EXPECT_EQ(e.pointer, "/onto/edge");
  }
}

TEST(Placement, AnOffsetMovesTheContactAlongTheSupportsEdgeOrItsX) {
  const Eigen::Isometry3d face = Eigen::Translation3d(1, 2, 0.5) * Eigen::AngleAxisd(0.5, Eigen::Vector3d::UnitZ());
  const Eigen::Vector3d edge = face.linear() * Eigen::Vector3d(0, 1, 0) + 0.3 * face.linear().col(2);  // a bit off-plane
  EXPECT_TRUE((offset_along(face, edge, 0.25).translation() - (face.translation() + 0.25 * face.linear().col(1))).norm() < 1e-12);
  EXPECT_TRUE((offset_along(face, std::nullopt, -0.1).translation() - (face.translation() - 0.1 * face.linear().col(0))).norm() < 1e-12);
  EXPECT_TRUE(offset_along(face, edge, 0.25).linear().isApprox(face.linear()));
  // Parsed: both edges or neither, a bounded offset.
  const json body = {{"model", "object:load"}, {"face", 4}, {"point_m", {0, 0, -0.1}}, {"edge", 3}, {"offset_m", 0.05},
                     {"onto", {{"model", "object:target"}, {"face", 2}, {"point_m", {0, 0, 0}}, {"edge", 7}}}};
  const PlaceRequest r = parse_place_request(body);
  EXPECT_EQ(r.own_edge, 3);
  EXPECT_EQ(r.onto_edge, 7);
  EXPECT_EQ(r.offset_m, 0.05);
  json one = body;
  one["onto"].erase("edge");
  EXPECT_THROW(parse_place_request(one), PlannerError);
  json far = body;
  far["offset_m"] = 11;
  EXPECT_THROW(parse_place_request(far), PlannerError);
}

/// A box's eight corners as the CAD service's features answer lists its vertices.
json box_vertices(const Eigen::Vector3d& low, const Eigen::Vector3d& high) {
  json vertices = json::array();
  for (int i = 0; i < 8; ++i)
    vertices.push_back({{"point_m", {(i & 1) ? high.x() : low.x(), (i & 2) ? high.y() : low.y(), (i & 4) ? high.z() : low.z()}}});
  return {{"vertices", vertices}};
}

TEST(Placement, APartTakingTheRopeHangsWhereTheLoadHungAndTheLoadStandsWhereThePartStood) {
  // The load (a 0.2 m box, frame at its centre) hangs at (3.5, 1.75, 1.2) turned 90°, hooked 0.1 m above its
  // centre; the part (frame at its bottom, 0.3 m high) stands on the floor at (6, 0, 0).
  const json doc = json::parse(R"({"cell_version": 1, "entities": [
    {"id": "load", "kind": "object", "parent": "world", "pose": {"position_m": [3.5, 1.75, 1.2], "rpy_deg": [0, 0, 90]},
     "features": {"rope_attachment": {"position_m": [0, 0, 0.1], "rpy_deg": [0, 0, 0]}}},
    {"id": "part", "kind": "object", "parent": "world", "pose": {"position_m": [6, 0, 0.001], "rpy_deg": [0, 0, 0]}}]})");
  const json load = box_vertices({-0.2, -0.15, -0.1}, {0.2, 0.15, 0.1});
  const json part = box_vertices({-0.2, -0.15, 0.0}, {0.2, 0.15, 0.3});
  const Eigen::Vector3d sling(-0.08, 0.0, 0.32);
  const json out = cell_with_load_exchanged(doc, "part", sling, part, "load", load);
  const Eigen::Isometry3d hung = pose_in(out, "part"), set_down = pose_in(out, "load");
  // Its sling straight under the hook (3.5, 1.75, 1.3), its bottom as high as the load's was (1.1), level.
  EXPECT_LT(((hung * sling).head<2>() - Eigen::Vector2d(3.5, 1.75)).norm(), 1e-9) << (hung * sling).transpose();
  EXPECT_NEAR(hung.translation().z(), 1.1, 1e-9);
  EXPECT_TRUE(hung.linear().isApprox(Eigen::Matrix3d::Identity(), 1e-9));
  EXPECT_EQ(out["entities"][1]["localized"], false);
  // The load where the part stood, turned as it was, its bottom 1 mm above the floor.
  EXPECT_LT((set_down.translation() - Eigen::Vector3d(6, 0, 0.101)).norm(), 1e-9) << set_down.translation().transpose();
  EXPECT_TRUE(set_down.linear().isApprox(pose_in(doc, "load").linear(), 1e-9));
  EXPECT_THROW(cell_with_load_exchanged(doc, "part", sling, json::object(), "load", load), PlannerError) << "no vertex";
  EXPECT_THROW(cell_with_load_exchanged(doc, "part", sling, part, "nobody", load), PlannerError);
}

}  // namespace
}  // namespace rigger::console
