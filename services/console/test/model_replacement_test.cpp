// A new version of an object's STEP model: the rules that still resolve on it are kept, the ones that do
// not (a hole that moved) are dropped and named; the object keeps its id, pose and features' names. Where
// a reference lands is the CAD service's answer (its `resolve` derivation, tested with the service): here
// a stand-in that knows the plate's three faces.
#include <gtest/gtest.h>

#include "model_replacement.hpp"
#include "planner.hpp"

namespace rigger::console {
namespace {

using nlohmann::json;

json sig(const char* type, json centroid, json direction, double radius = 0) {
  return {{"type", type}, {"centroid_m", centroid}, {"direction", direction}, {"radius_m", radius}};
}

json ref(int index, const json& signature) { return {{"kind", "face"}, {"index", index}, {"signature", signature}}; }

const json kTop = sig("plane", {0, 0, 0.02}, {0, 0, 1});
json hole_at(double x) { return sig("cylinder", {x, 0.1, 0.01}, {0, 0, 1}, 0.0051); }

// The CAD service's answer on a plate whose second hole is at x = `second_x` (face 2; the first at -0.1,
// the top face 0): a reference resolves when its signature's centroid is one of these, else it is stale.
// Counts the questions and keeps the references asked.
struct PlateResolver {
  explicit PlateResolver(double x) : second_x(x) {}
  double second_x;
  int calls = 0;
  std::vector<json> asked;
  std::vector<std::string> operator()(const std::vector<json>& refs) {
    ++calls;
    asked = refs;
    std::vector<std::string> why;
    for (const json& r : refs) {
      const json& c = r["signature"]["centroid_m"];
      const bool there = c == kTop["centroid_m"] || c == hole_at(-0.1)["centroid_m"] || c == hole_at(second_x)["centroid_m"];
      why.push_back(there ? "" : "face " + r["index"].dump() + " no longer exists");
    }
    return why;
  }
};
Resolver resolver(PlateResolver& p) { return [&p](const std::vector<json>& refs) { return p(refs); }; }

// The plate (its grasp on the top, screw holes m1, m2) and a bracket inserted into it, pinned by m2's hole.
json cell() {
  const auto hole_rule = [](int face, double x) { return json{{"rule", "hole"}, {"hole", ref(face, hole_at(x))}}; };
  return {{"cell_version", 1},
          {"entities",
           {{{"id", "plate"},
             {"model", {{"step", "imported/plate.step"}, {"sha256", std::string(64, 'a')}}},
             {"features",
              {{"grasp_frames", {{{"id", "top"}, {"cad", {{"rule", "face"}, {"face", ref(0, kTop)}}}}}},
               {"screw_holes",
                {{{"id", "m1"}, {"cad", hole_rule(1, -0.1)}, {"screw_type", "M10"}, {"torque_nm", 40}},
                 {{"id", "m2"}, {"cad", hole_rule(2, 0.1)}, {"screw_type", "M10"}, {"torque_nm", 40}}}}}}},
            {{"id", "bracket"},
             {"features",
              {{"insertion",
                {{"target", "plate"},
                 {"cad",
                  {{"rule", "mate_faces"},
                   {"face", ref(0, kTop)},
                   {"target_face", ref(0, kTop)},
                   {"pins", {{{"hole", ref(1, hole_at(-0.1))}, {"target_hole", ref(2, hole_at(0.1))}}}}}}}}}}}}}};
}

const ReplaceRequest kRequest{std::string(64, 'b'), "plate", ""};

TEST(ModelReplacement, AHoleThatMovedIsDroppedWithItsPinTheRestKept) {
  // The new model's second hole is 2 mm further along x. Every reference goes in one question: the grasp's
  // face, the two holes, the bracket's insertion's target face and its pin's target hole.
  PlateResolver cad{0.102};
  const Replacement r = cell_with_replaced_model(cell(), kRequest, resolver(cad));
  EXPECT_EQ(cad.calls, 1);
  EXPECT_EQ(cad.asked.size(), 5u);
  const json& plate = r.cell["entities"][0];
  EXPECT_EQ(plate["model"]["sha256"], std::string(64, 'b'));
  EXPECT_EQ(plate["model"]["step"], "imported/plate-bbbbbbbbbbbb.step");
  EXPECT_EQ(r.kept, (std::vector<std::string>{"plate/top", "plate/m1"}));
  ASSERT_EQ(r.dropped.size(), 2u);
  EXPECT_EQ(r.dropped[0].feature, "plate/m2");
  EXPECT_EQ(r.dropped[0].why, "hole: face 2 no longer exists");
  EXPECT_EQ(r.dropped[1].feature, "bracket/insertion");  // its pin is on the hole that moved
  EXPECT_EQ(plate["features"]["screw_holes"].size(), 1u);
  EXPECT_EQ(plate["features"]["screw_holes"][0]["id"], "m1");
  EXPECT_FALSE(r.cell["entities"][1]["features"].contains("insertion"));
}

TEST(ModelReplacement, TheSameGeometryKeepsEveryRule) {
  // Another file (another sha256) of the same geometry: a re-export with a new header.
  PlateResolver cad{0.1};
  const Replacement r = cell_with_replaced_model(cell(), kRequest, resolver(cad));
  EXPECT_TRUE(r.dropped.empty()) << r.dropped.front().feature << ": " << r.dropped.front().why;
  EXPECT_EQ(r.kept, (std::vector<std::string>{"plate/top", "plate/m1", "plate/m2", "bracket/insertion"}));
}

TEST(ModelReplacement, AnObjectWithoutAStepModelOrTheSameModelIsRefused) {
  const auto refused = [](const json& c, const ReplaceRequest& request) {
    try {
      PlateResolver cad{0.1};
      cell_with_replaced_model(c, request, resolver(cad));
    } catch (const PlannerError& e) {
      return e.pointer + ": " + e.message;
    }
    return std::string("accepted");
  };
  EXPECT_EQ(refused(cell(), {std::string(64, 'b'), "nowhere", ""}).substr(0, 9), "/object: ");
  EXPECT_NE(refused(cell(), {std::string(64, 'b'), "bracket", ""}).find("not given by a STEP model"), std::string::npos);
  EXPECT_NE(refused(cell(), {std::string(64, 'a'), "plate", ""}).find("has this model already"), std::string::npos);
  // A CAD service that does not answer for every reference refuses the replacement.
  const Resolver short_answer = [](const std::vector<json>&) { return std::vector<std::string>{""}; };
  try {
    cell_with_replaced_model(cell(), kRequest, short_answer);
    ADD_FAILURE() << "accepted an answer for 1 of 5 references";
  } catch (const PlannerError& e) {
    EXPECT_EQ(e.pointer, "/model");
    EXPECT_NE(e.message.find("resolved 1 of 5 references"), std::string::npos) << e.message;
  }
  EXPECT_THROW(parse_replace_request({{"model", "sha256:12"}, {"object", "plate"}}), PlannerError);
  EXPECT_EQ(parse_replace_request({{"model", "sha256:" + std::string(64, 'c')}, {"object", "plate"}}).object, "plate");
}

}  // namespace
}  // namespace rigger::console
