// The CAD service's answers on the real cell file and its STEP models, and on bad and hostile requests.

#include "cad_service.hpp"

#include <Eigen/Core>

#include "rigger/base/sha256.hpp"
#include "rigger/cad/parts.hpp"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <iterator>
#include <unistd.h>
#include <nlohmann/json.hpp>

namespace rigger::cad_service {
namespace {

using nlohmann::json;

CadServiceSettings settings() {
  CadServiceSettings s;
  s.cell_file = RIGGER_SOURCE_DIR "/deploy/cell/simulated_cell.json";
  s.allowed_dirs = {"/usr/share/opencascade/data/step"};
  return s;
}

CadAnswer ask(CadService& service, QueryKind kind, const std::string& model, const std::string& args = "",
              const std::string& content = "") {
  return service.answer(CadQuery{kind, model, content, args});
}

TEST(CadService, ObjectModelsFromTheCellFile) {
  CadService service(settings());
  EXPECT_EQ(service.object_status().size(), 4u);  // load, target, part, part_fixture
  const CadAnswer load = ask(service, QueryKind::kLoad, "object:load");
  ASSERT_TRUE(load.ok) << load.message;
  EXPECT_EQ(json::parse(load.result_json)["product"]["name"], "load");
  const CadAnswer features = ask(service, QueryKind::kFeatures, "object:target");
  ASSERT_TRUE(features.ok) << features.message;
  const json f = json::parse(features.result_json);
  EXPECT_EQ(f["holes"].size(), 4u);
  EXPECT_EQ(f["faces"].size(), f["counts"]["faces"].get<std::size_t>());
  // The same model by its sha256.
  EXPECT_TRUE(ask(service, QueryKind::kFeatures, "sha256:" + features.model_sha256).ok);
}

TEST(CadService, ANewCellRevisionReplacesTheObjectModels) {
  CadService service(settings());
  const std::string target_sha = ask(service, QueryKind::kLoad, "object:target").model_sha256;
  // The revision: `part` removed, a new object `bracket` with the target's model, `load` unchanged.
  std::ifstream in(settings().cell_file, std::ios::binary);
  json cell = json::parse(std::string(std::istreambuf_iterator<char>(in), {}));
  json kept = json::array();
  for (json& entity : cell["entities"]) {
    if (entity["id"] == "part") continue;
    if (entity["id"] == "target") {
      json bracket = entity;
      bracket["id"] = "bracket";
      bracket["model"].erase("static");
      bracket["model"]["mass_kg"] = 5.0;
      bracket.erase("features");
      kept.push_back(bracket);
    }
    kept.push_back(entity);
  }
  cell["entities"] = kept;
  const cell::CellFile revision = cell::cell_file_from_json(cell, "revision 2");
  service.follow(revision, settings().cell_file.parent_path());
  EXPECT_EQ(ask(service, QueryKind::kLoad, "object:part").code, "CAD_UNKNOWN_MODEL");
  const CadAnswer bracket = ask(service, QueryKind::kLoad, "object:bracket");
  ASSERT_TRUE(bracket.ok) << bracket.message;
  EXPECT_EQ(bracket.model_sha256, target_sha);
  EXPECT_TRUE(ask(service, QueryKind::kFeatures, "object:load").ok);
  EXPECT_EQ(service.object_status().count("bracket"), 1u);
}

TEST(CadService, APinnedObjectModelIsServedOnlyWithItsBytes) {
  CadService service(settings());
  const std::string load_sha = ask(service, QueryKind::kLoad, "object:load").model_sha256;
  const std::string target_sha = ask(service, QueryKind::kLoad, "object:target").model_sha256;
  // The revision pins the target to its own bytes and the load to the target's: the load file already
  // loaded is not taken as it is, it is refused.
  std::ifstream in(settings().cell_file, std::ios::binary);
  json cell = json::parse(std::string(std::istreambuf_iterator<char>(in), {}));
  for (json& entity : cell["entities"]) {
    if (entity["id"] == "target") entity["model"]["sha256"] = target_sha;
    if (entity["id"] == "load") entity["model"]["sha256"] = target_sha;
  }
  service.follow(cell::cell_file_from_json(cell, "revision 2"), settings().cell_file.parent_path());
  const CadAnswer load = ask(service, QueryKind::kLoad, "object:load");
  EXPECT_EQ(load.code, "CAD_STALE_MODEL") << load.message;
  EXPECT_NE(load.message.find(load_sha), std::string::npos) << load.message;
  const CadAnswer target = ask(service, QueryKind::kLoad, "object:target");
  ASSERT_TRUE(target.ok) << target.message;
  EXPECT_EQ(target.model_sha256, target_sha);
}

TEST(CadService, TessellationOfTheTarget) {
  CadService service(settings());
  const CadAnswer mesh = ask(service, QueryKind::kTessellation, "object:target");
  ASSERT_TRUE(mesh.ok) << mesh.message;
  ASSERT_GT(mesh.data.size(), 100u);
  EXPECT_EQ(std::string(mesh.data.begin(), mesh.data.begin() + 4), "glTF");
  const json parts = json::parse(mesh.result_json)["parts"];
  EXPECT_EQ(parts.size(), 14u);  // one per face of the target
  EXPECT_EQ(parts[0]["ref"]["kind"], "face");
}

TEST(CadService, FramesAndDerivedParameters) {
  CadService service(settings());
  CadAnswer hole = ask(service, QueryKind::kFrame, "object:target", R"({"rule": "hole", "hole": 0})");
  ASSERT_TRUE(hole.ok) << hole.message;
  EXPECT_NEAR(json::parse(hole.result_json)["frame"]["position_m"][0].get<double>(), -0.15, 1e-9);
  // The shipped load, a 0.40 x 0.30 x 0.20 m box about its centre: its sling 20 mm above its top, over its centre.
  const CadAnswer sling = ask(service, QueryKind::kFrame, "object:load", R"({"rule": "above_centre_of_mass"})");
  ASSERT_TRUE(sling.ok) << sling.message;
  const json at = json::parse(sling.result_json)["frame"]["position_m"];
  EXPECT_LT(Eigen::Vector3d(at[0].get<double>(), at[1].get<double>(), at[2].get<double>() - 0.12).norm(), 1e-6) << at;
  const CadAnswer screws = ask(service, QueryKind::kDerive, "object:target", R"({"parameter": "screw_list"})");
  ASSERT_TRUE(screws.ok) << screws.message;
  EXPECT_EQ(json::parse(screws.result_json)["screws"].size(), 4u);
  // A reference whose signature no longer matches is refused as stale, not silently used.
  const json features = json::parse(ask(service, QueryKind::kFeatures, "object:load").result_json);
  json face = {{"kind", "face"}, {"index", 0}, {"model_sha256", features["model_sha256"]},
               {"signature", features["faces"][0]["signature"]}};
  face["signature"]["centroid_m"][0] = face["signature"]["centroid_m"][0].get<double>() + 0.01;
  const json point = features["faces"][0]["signature"]["centroid_m"];
  CadAnswer stale = ask(service, QueryKind::kFrame, "object:load", json{{"rule", "face"}, {"face", face}, {"point_m", point}}.dump());
  EXPECT_FALSE(stale.ok);
  EXPECT_EQ(stale.code, "CAD_STALE_REFERENCE") << stale.message;
  face["signature"] = features["faces"][0]["signature"];
  CadAnswer fresh = ask(service, QueryKind::kFrame, "object:load", json{{"rule", "face"}, {"face", face}, {"point_m", point}}.dump());
  EXPECT_TRUE(fresh.ok) << fresh.message;
}

TEST(CadService, ScrewListOfPickedHolesInThePickedOrder) {
  CadService service(settings());
  const json features = json::parse(ask(service, QueryKind::kFeatures, "object:target").result_json);
  ASSERT_EQ(features["holes"].size(), 4u);
  // Hole 2 by a reference to its face, then hole 0 by index: the screws come in that order, each with
  // its face reference and the same frame as the hole rule gives.
  const int face2 = features["holes"][2]["faces"][0];
  const json ref2 = {{"model_sha256", features["model_sha256"]}, {"kind", "face"}, {"index", face2},
                     {"signature", features["faces"][face2]["signature"]}};
  const CadAnswer picked = ask(service, QueryKind::kDerive, "object:target",
                               json{{"parameter", "screw_list"}, {"holes", json::array({ref2, 0})}}.dump());
  ASSERT_TRUE(picked.ok) << picked.message;
  const json screws = json::parse(picked.result_json)["screws"];
  ASSERT_EQ(screws.size(), 2u);
  EXPECT_EQ(screws[0]["hole"], 2);
  EXPECT_EQ(screws[1]["hole"], 0);
  EXPECT_EQ(screws[0]["ref"], ref2);
  EXPECT_EQ(screws[0]["pose"]["position_m"], features["holes"][2]["entry_m"]);
  const json frame0 = json::parse(ask(service, QueryKind::kFrame, "object:target", R"({"rule": "hole", "hole": 0})").result_json);
  EXPECT_EQ(screws[1]["pose"], frame0["frame"]);

  // Bad picks say which one and why.
  const CadAnswer out_of_range = ask(service, QueryKind::kDerive, "object:target", R"({"parameter": "screw_list", "holes": [0, 9]})");
  EXPECT_EQ(out_of_range.code, "CAD_BAD_REFERENCE");
  EXPECT_NE(out_of_range.message.find("holes[1]: no hole 9"), std::string::npos) << out_of_range.message;
  int plane = -1;
  for (const auto& f : features["faces"])
    if (f["signature"]["type"] == "plane") plane = f["index"];
  ASSERT_GE(plane, 0);
  const json plane_ref = {{"model_sha256", features["model_sha256"]}, {"kind", "face"}, {"index", plane},
                          {"signature", features["faces"][plane]["signature"]}};
  const CadAnswer plane_face = ask(service, QueryKind::kDerive, "object:target",
                                   json{{"parameter", "screw_list"}, {"holes", json::array({plane_ref})}}.dump());
  EXPECT_EQ(plane_face.code, "CAD_BAD_REFERENCE");
  EXPECT_NE(plane_face.message.find("is not a face of a hole"), std::string::npos) << plane_face.message;
  EXPECT_EQ(ask(service, QueryKind::kDerive, "object:target", R"({"parameter": "screw_list", "holes": []})").code,
            "CAD_BAD_REQUEST");
}

TEST(CadService, ResolveSaysWhereEachReferenceLandsOrWhyItIsStale) {
  CadService service(settings());
  const json features = json::parse(ask(service, QueryKind::kFeatures, "object:target").result_json);
  const auto ref = [&](int index) {
    return json{{"model_sha256", features["model_sha256"]}, {"kind", "face"}, {"index", index},
                {"signature", features["faces"][index]["signature"]}};
  };
  // Face 3 as it is; face 5's reference under index 7 (renumbered: its signature finds it); a face whose
  // centroid moved 2 mm.
  json renumbered = ref(5);
  renumbered["index"] = 7;
  json moved = ref(2);
  moved["signature"]["centroid_m"][0] = moved["signature"]["centroid_m"][0].get<double>() + 0.002;
  const CadAnswer answer = ask(service, QueryKind::kDerive, "object:target",
                               json{{"parameter", "resolve"}, {"references", {ref(3), renumbered, moved}}}.dump());
  ASSERT_TRUE(answer.ok) << answer.message;
  const json resolved = json::parse(answer.result_json)["resolved"];
  ASSERT_EQ(resolved.size(), 3u) << resolved.dump();
  EXPECT_EQ(resolved[0], (json{{"index", 3}}));
  EXPECT_EQ(resolved[1], (json{{"index", 5}}));
  ASSERT_TRUE(resolved[2].contains("stale")) << resolved.dump();
  EXPECT_NE(resolved[2]["stale"].get<std::string>().find("face 2 ("), std::string::npos) << resolved[2];
  EXPECT_NE(resolved[2]["stale"].get<std::string>().find(" mm) of model "), std::string::npos) << resolved[2];

  // What is not a list of references is refused, saying which.
  EXPECT_EQ(ask(service, QueryKind::kDerive, "object:target", R"({"parameter": "resolve"})").code, "CAD_BAD_REQUEST");
  const CadAnswer bad = ask(service, QueryKind::kDerive, "object:target",
                            json{{"parameter", "resolve"}, {"references", {ref(3), {{"kind", "solid"}}}}}.dump());
  EXPECT_EQ(bad.code, "CAD_BAD_REFERENCE");
  EXPECT_NE(bad.message.find("references[1]: "), std::string::npos) << bad.message;
}

TEST(CadService, BadRequestsAreAnsweredWithACode) {
  CadService service(settings());
  EXPECT_EQ(ask(service, QueryKind::kFeatures, "object:crane").code, "CAD_UNKNOWN_MODEL");
  EXPECT_EQ(ask(service, QueryKind::kFeatures, "sha256:0000").code, "CAD_UNKNOWN_MODEL");
  EXPECT_EQ(ask(service, QueryKind::kFeatures, "/etc/passwd").code, "CAD_FORBIDDEN_PATH");
  EXPECT_EQ(ask(service, QueryKind::kFeatures, "/usr/share/opencascade/data/step/../../../../../etc/passwd").code,
            "CAD_FORBIDDEN_PATH");
  EXPECT_EQ(ask(service, QueryKind::kFeatures, "").code, "CAD_BAD_REQUEST");
  EXPECT_EQ(ask(service, QueryKind::kFrame, "object:target", "{not json").code, "CAD_BAD_REQUEST");
  EXPECT_EQ(ask(service, QueryKind::kFrame, "object:target", R"({"rule": "magic"})").code, "CAD_BAD_REQUEST");
  EXPECT_EQ(ask(service, QueryKind::kFrame, "object:target", R"({"rule": "hole", "hole": 9})").code, "CAD_BAD_REFERENCE");
  EXPECT_EQ(ask(service, QueryKind::kFrame, "object:target", R"({"rule": "edges", "point_m": [0,0,0], "edges": [0, 0]})").code,
            "CAD_NOT_A_FRAME");
  EXPECT_EQ(ask(service, QueryKind::kDerive, "object:target", R"({"parameter": "x"})").code, "CAD_BAD_REQUEST");
  // args_json comes from another process: bounded while parsed, the refusal says where.
  const CadAnswer deep = ask(service, QueryKind::kFrame, "object:target", std::string(1000, '['));
  EXPECT_EQ(deep.code, "CAD_BAD_REQUEST");
  EXPECT_NE(deep.message.find("args_json: 1:17:"), std::string::npos) << deep.message;
  const CadAnswer twice = ask(service, QueryKind::kFrame, "object:target", R"({"rule": "hole", "rule": "edges"})");
  EXPECT_EQ(twice.code, "CAD_BAD_REQUEST");
  EXPECT_NE(twice.message.find("duplicate"), std::string::npos) << twice.message;
}

TEST(CadService, HostileContentIsRefusedAndTheServiceGoesOn) {
  CadService service(settings());
  EXPECT_EQ(ask(service, QueryKind::kLoad, "", "", std::string("\x00\x01junk", 6)).code, "CAD_NOT_STEP");
  std::ifstream in("/usr/share/opencascade/data/step/screw.step", std::ios::binary);
  const std::string screw((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const CadAnswer truncated = ask(service, QueryKind::kLoad, "", "", screw.substr(0, screw.size() / 3));
  EXPECT_FALSE(truncated.ok);
  EXPECT_FALSE(truncated.message.empty());
  const CadAnswer whole = ask(service, QueryKind::kLoad, "", "", screw);
  ASSERT_TRUE(whole.ok) << whole.message;
  EXPECT_TRUE(ask(service, QueryKind::kFeatures, "sha256:" + whole.model_sha256).ok);
  EXPECT_TRUE(ask(service, QueryKind::kFeatures, "/usr/share/opencascade/data/step/screw.step").ok);
}

// A node of an assembly sent as content (CAD_LOAD with args_json.node): its own STEP bytes in data, named
// by their sha256, answered like a load; a node that does not exist, a bad path and a model the service
// has no bytes of are refused with a code and where.
TEST(CadService, ANodeOfAnAssemblyIsLoadedAsAModelOfItsOwn) {
  CadService service(settings());
  const std::filesystem::path file =
      std::filesystem::temp_directory_path() / ("rigger_cad_service_assembly_" + std::to_string(::getpid()) + ".step");
  cad::write_step_assembly(cad::parts::test_assembly(), file);
  std::ifstream in(file, std::ios::binary);
  const std::string assembly((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  std::filesystem::remove(file);
  const CadAnswer frame = ask(service, QueryKind::kLoad, "assembly.step", R"({"node": [0]})", assembly);
  ASSERT_TRUE(frame.ok) << frame.code << " " << frame.message;
  const std::string step(frame.data.begin(), frame.data.end());
  EXPECT_EQ(frame.model_sha256, sha256_hex(step));
  const json result = json::parse(frame.result_json);
  EXPECT_EQ(result["node"]["name"], "frame");
  EXPECT_EQ(result["node"]["instance"], "frame_1");
  EXPECT_EQ(result["node"]["path"], json::array({0}));
  EXPECT_NEAR(result["node"]["pose_in_file"]["position_m"][0].get<double>(), 1.0, 1e-9);
  EXPECT_EQ(result["product"]["name"], "frame");
  EXPECT_EQ(result["counts"]["holes"], 5);
  EXPECT_EQ(result["counts"]["solids"], 2);
  // The node's model is served by its sha256; the same node again gives the same model.
  EXPECT_TRUE(ask(service, QueryKind::kFeatures, "sha256:" + frame.model_sha256).ok);
  EXPECT_EQ(ask(service, QueryKind::kLoad, "assembly.step", R"({"node": [0]})", assembly).model_sha256, frame.model_sha256);
  const CadAnswer missing = ask(service, QueryKind::kLoad, "assembly.step", R"({"node": [1, 5]})", assembly);
  EXPECT_EQ(missing.code, "CAD_BAD_REFERENCE");
  EXPECT_NE(missing.message.find("node 1 ('pair') has 2 components"), std::string::npos) << missing.message;
  EXPECT_EQ(ask(service, QueryKind::kLoad, "assembly.step", R"({"node": ["0"]})", assembly).code, "CAD_BAD_REQUEST");
  EXPECT_EQ(ask(service, QueryKind::kLoad, "assembly.step", R"({"node": [-1]})", assembly).code, "CAD_BAD_REQUEST");
  EXPECT_EQ(ask(service, QueryKind::kLoad, "assembly.step", R"({"node": 0})", assembly).code, "CAD_BAD_REQUEST");
  const json deep = {{"node", std::vector<int>(33, 0)}};
  EXPECT_EQ(ask(service, QueryKind::kLoad, "assembly.step", deep.dump(), assembly).code, "CAD_BAD_REQUEST");
  const CadAnswer no_bytes = ask(service, QueryKind::kLoad, "sha256:" + frame.model_sha256, R"({"node": [0]})");
  EXPECT_EQ(no_bytes.code, "CAD_BAD_REQUEST");
  EXPECT_NE(no_bytes.message.find("send its bytes in content"), std::string::npos) << no_bytes.message;
  // A cell object's own file: its root (a part) is a node too.
  const CadAnswer target = ask(service, QueryKind::kLoad, "object:target", R"({"node": []})");
  ASSERT_TRUE(target.ok) << target.message;
  EXPECT_EQ(json::parse(target.result_json)["counts"]["holes"], 4);
}

}  // namespace
}  // namespace rigger::cad_service
