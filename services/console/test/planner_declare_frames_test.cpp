// The rope attachment and markers declared at a CAD frame: the pose written into the document, the
// marker's corners on the face frame, and the refusals at their fields.
#include <gtest/gtest.h>

#include "planner_declare_frames.hpp"

namespace rigger::console {
namespace {

using nlohmann::json;

json cell() {
  return {{"cell_version", 1},
          {"entities",
           {{{"id", "target"},
             {"features", {{"markers", {{"dictionary", "DICT_4X4_50"}, {"items", {{{"id", 10}, {"size_m", 0.1}}}}}}}}},
            {{"id", "plate"}}}}};
}

// The +x face of a part at (0.2, 0, 0.05): z out along +x.
Eigen::Isometry3d side_face() {
  Eigen::Isometry3d at = Eigen::Isometry3d::Identity();
  at.linear() << 0, 0, 1, 1, 0, 0, 0, 1, 0;  // columns: x = +y, y = +z, z = +x
  at.translation() = Eigen::Vector3d(0.2, 0, 0.05);
  return at;
}

DeclareRequest marker(json extra) {
  json body = {{"model", "object:plate"}, {"kind", "marker"}, {"face", 3}, {"point_m", {0.2, 0, 0.05}},
               {"dictionary", "DICT_4X4_50"}, {"marker_id", 12}, {"size_m", 0.08}};
  if (extra.is_object()) body.update(extra);
  return parse_declare_request(body);
}

std::string refusal(const DeclareRequest& r) {
  try {
    declare_at_frame(r, cell(), side_face());
  } catch (const PlannerError& e) {
    return e.pointer + ": " + e.message;
  }
  return "accepted";
}

TEST(PlannerDeclareFrames, AMarkerIsASquareOnTheFaceAtThePickedPoint) {
  const DeclareRequest r = marker({});
  EXPECT_EQ(frame_args(r), json({{"rule", "face"}, {"face", 3}, {"point_m", {0.2, 0, 0.05}}}));
  const auto corners = marker_corners(r, side_face());
  for (const Eigen::Vector3d& c : corners) {
    EXPECT_NEAR(c.x(), 0.2, 1e-12) << "a corner off the face's plane";
    EXPECT_NEAR(std::abs(c.y()), 0.04, 1e-12);
    EXPECT_NEAR(std::abs(c.z() - 0.05), 0.04, 1e-12);
  }
  const json out = declare_at_frame(r, cell(), side_face());
  const json& m = out.at("cell").at("entities").at(1).at("features").at("markers");
  EXPECT_EQ(m.at("dictionary"), "DICT_4X4_50");
  ASSERT_EQ(m.at("items").size(), 1U);
  EXPECT_EQ(m.at("items")[0].at("id"), 12);
  EXPECT_EQ(m.at("items")[0].at("size_m"), 0.08);
  EXPECT_EQ(m.at("items")[0].at("pose").at("position_m"), json({0.2, 0.0, 0.05}));
  EXPECT_EQ(out.at("features"), json({"plate/marker 12"}));
}

TEST(PlannerDeclareFrames, MarkersRefusedAtTheirField) {
  EXPECT_EQ(refusal(marker({{"marker_id", 10}})).substr(0, 11), "/marker_id:") << "10 is on the target";
  EXPECT_EQ(refusal(marker({{"marker_id", 50}})).substr(0, 11), "/marker_id:") << "DICT_4X4_50 has ids 0..49";
  EXPECT_EQ(refusal(marker({{"dictionary", "DICT_9X9"}})).substr(0, 12), "/dictionary:");
  EXPECT_THROW(marker_corners(marker({{"size_m", 0.001}}), side_face()), PlannerError);
  json body = {{"model", "object:plate"}, {"kind", "marker"}, {"face", 3}};
  EXPECT_THROW(frame_args(parse_declare_request(body)), PlannerError) << "a marker needs the picked point";
  // One dictionary per object.
  json two = declare_at_frame(marker({}), cell(), side_face()).at("cell");
  try {
    declare_at_frame(marker({{"dictionary", "DICT_5X5_50"}, {"marker_id", 13}}), two, side_face());
    ADD_FAILURE() << "a second dictionary on one object";
  } catch (const PlannerError& e) {
    EXPECT_EQ(e.pointer, "/dictionary");
  }
}

TEST(PlannerDeclareFrames, TheRopeAttachmentIsAPickedHoleOrAFacePointOncePerPart) {
  const DeclareRequest hole = parse_declare_request({{"model", "object:plate"}, {"kind", "rope_attachment"}, {"hole", 2}});
  EXPECT_EQ(frame_args(hole), json({{"rule", "hole"}, {"hole", 2}}));
  const json out = declare_at_frame(hole, cell(), side_face());
  const json& rope = out.at("cell").at("entities").at(1).at("features").at("rope_attachment");
  EXPECT_EQ(rope.at("position_m"), json({0.2, 0.0, 0.05}));
  EXPECT_EQ(out.at("features"), json({"plate/rope_attachment"}));
  EXPECT_THROW(declare_at_frame(hole, out.at("cell"), side_face()), PlannerError) << "a second rope attachment";
  EXPECT_FALSE(out.contains("rope_from")) << "no other object had the rope";
  // The crane carries one load: declared on another object, the rope moves there from the plate.
  const DeclareRequest on_target = parse_declare_request({{"model", "object:target"}, {"kind", "rope_attachment"}, {"hole", 2}});
  const json moved = declare_at_frame(on_target, out.at("cell"), side_face());
  EXPECT_EQ(moved.at("rope_from"), "plate");
  EXPECT_TRUE(moved.at("cell").at("entities").at(0).at("features").contains("rope_attachment"));
  EXPECT_FALSE(moved.at("cell").at("entities").at(1).at("features").contains("rope_attachment"));
  EXPECT_THROW(frame_args(parse_declare_request({{"model", "object:plate"}, {"kind", "rope_attachment"}})), PlannerError);
  EXPECT_EQ(rope_holder(moved.at("cell"), "plate"), "target");
  EXPECT_EQ(rope_holder(moved.at("cell"), "target"), "");
}

TEST(PlannerDeclareFrames, ASlingAboveTheCentreOfMassNeedsNoPickAndNoFixedPartTakesTheRope) {
  const DeclareRequest sling =
      parse_declare_request({{"model", "object:plate"}, {"kind", "rope_attachment"}, {"above_centre_of_mass", true}});
  EXPECT_EQ(frame_args(sling), json({{"rule", "above_centre_of_mass"}}));
  EXPECT_THROW(frame_args(parse_declare_request(
                   {{"model", "object:plate"}, {"kind", "rope_attachment"}, {"above_centre_of_mass", "yes"}})),
               PlannerError);
  json fixed = cell();
  fixed["entities"][1]["model"] = {{"static", true}};
  try {
    declare_at_frame(sling, fixed, side_face());
    ADD_FAILURE() << "a fixed part took the rope";
  } catch (const PlannerError& e) {
    EXPECT_EQ(e.pointer, "/model");
    EXPECT_NE(e.message.find("\"plate\" is fixed"), std::string::npos) << e.message;
  }
}

TEST(PlannerDeclareFrames, AMarkerACameraSeesTooFlatIsNamedWithItsAngle) {
  json with_camera = cell();
  with_camera["entities"].push_back({{"id", "camera"}, {"kind", "device"}, {"parent", "world"},
                                     {"pose", {{"position_m", {1.55, 0, 0.62}}, {"rpy_deg", {0, 0, 0}}}},
                                     {"camera", json::object()}});
  // On the plate's top face at its origin: a camera 22 degrees above the horizon sees it 68 degrees off.
  const std::string note = marker_view_note(with_camera, "plate", 40, Eigen::Isometry3d::Identity());
  EXPECT_NE(note.find("Camera camera sees marker 40 at 68 degrees from its normal where plate stands now"),
            std::string::npos)
      << note;
  // On the side facing the camera (23 degrees off), or with no camera in the cell: nothing to say.
  EXPECT_EQ(marker_view_note(with_camera, "plate", 40, side_face()), "");
  EXPECT_EQ(marker_view_note(cell(), "plate", 40, Eigen::Isometry3d::Identity()), "");
}

}  // namespace
}  // namespace rigger::console
