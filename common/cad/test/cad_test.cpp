// rigger_cad on parts of known geometry (built with OCCT, written to STEP and read back), on STEP files
// rigger did not make (Debian's occt-misc samples), and on bad input.

#include "rigger/cad/cad_json.hpp"
#include "rigger/cad/features.hpp"
#include "rigger/cad/frames.hpp"
#include "rigger/cad/model.hpp"
#include "rigger/cad/parts.hpp"
#include "rigger/cad/tessellation.hpp"
#include "step_file_test.hpp"

#include <BRepGProp.hxx>
#include <BRepBuilderAPI_MakeSolid.hxx>
#include <BRepPrimAPI_MakeBox.hxx>
#include <BRep_Builder.hxx>
#include <TopExp_Explorer.hxx>
#include <TopoDS.hxx>
#include <TopoDS_Compound.hxx>
#include <TopoDS_Shell.hxx>
#include <TopoDS_Solid.hxx>
#include <GProp_GProps.hxx>
#include <STEPCAFControl_Writer.hxx>
#include <TDocStd_Document.hxx>
#include <TopExp.hxx>
#include <TopLoc_Location.hxx>
#include <TopTools_IndexedMapOfShape.hxx>
#include <XCAFApp_Application.hxx>
#include <XCAFDoc_DocumentTool.hxx>
#include <XCAFDoc_ShapeTool.hxx>
#include <gtest/gtest.h>
#include <unistd.h>

#include <cstring>
#include <fstream>
#include <nlohmann/json.hpp>

namespace rigger::cad {
namespace {

namespace fs = std::filesystem;
constexpr double kTolM = 1e-6;
constexpr double kTolRad = 1e-6;
const fs::path kOcctSamples = "/usr/share/opencascade/data/step";

using CadTest = StepFileTest;

// Every built hole is found once, within 1e-6 m / 1e-6 rad, and nothing else is taken for a hole.
void expect_holes(const Features& features, const std::vector<parts::DrilledHole>& expected) {
  ASSERT_EQ(features.holes.size(), expected.size());
  for (const auto& want : expected) {
    const Hole* found = nullptr;
    for (const auto& hole : features.holes) {
      if ((hole.entry_m - want.entry_m).norm() < 1e-4) {
        found = &hole;
      }
    }
    ASSERT_NE(found, nullptr) << "no hole at " << want.entry_m.transpose();
    EXPECT_LT((found->entry_m - want.entry_m).norm(), kTolM) << want.entry_m.transpose();
    EXPECT_LT(std::acos(std::min(1.0, found->axis.dot(want.axis))), kTolRad) << found->axis.transpose();
    EXPECT_NEAR(found->diameter_m, want.diameter_m, kTolM);
    EXPECT_NEAR(found->depth_m, want.depth_m, kTolM);
    EXPECT_EQ(found->through, want.through);
  }
}

TEST_F(CadTest, PlateHolesAreFoundAtTheirPositions) {
  const Model model = round_trip(parts::plate(), "plate");
  EXPECT_EQ(model.product().name, "plate");
  const Features features = classify(model);
  expect_holes(features, parts::plate_holes());
  EXPECT_EQ(features.solids, 1);
  EXPECT_EQ(features.count_faces("plane"), 6);
}

TEST_F(CadTest, StepIsWrittenInMillimetresAndReadInMetres) {
  const fs::path path = dir_ / "box.step";
  write_step(BRepPrimAPI_MakeBox(0.4, 0.3, 0.2).Shape(), "box", path);
  std::ifstream in(path);
  const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  EXPECT_NE(text.find(".MILLI."), std::string::npos);
  EXPECT_NE(text.find("400."), std::string::npos);
  const Features features = classify(read_step_file(path));
  double max_x = 0;
  for (const auto& v : features.vertices) {
    max_x = std::max(max_x, v.point_m.x());
  }
  EXPECT_NEAR(max_x, 0.4, 1e-12);
}

TEST_F(CadTest, BlockThroughAndBlindHoles) {
  const Features features = classify(round_trip(parts::block(), "block"));
  expect_holes(features, parts::block_holes());
}

TEST_F(CadTest, BossIsNotAHole) {
  const Features features = classify(round_trip(parts::boss_part(), "boss"));
  expect_holes(features, parts::boss_part_holes());
  int convex_cylinders = 0;
  for (const auto& face : features.faces) {
    convex_cylinders += face.signature.type == "cylinder" && !face.material_outside;
  }
  EXPECT_GE(convex_cylinders, 1);  // the boss is there, as a cylinder with material inside
}

TEST_F(CadTest, CellPartsHaveTheirScrewHoles) {
  const Eigen::Vector3d load_size(0.40, 0.30, 0.20), target_size(0.50, 0.40, 0.95);
  expect_holes(classify(round_trip(parts::cell_load(load_size), "load")), parts::cell_load_holes(load_size));
  expect_holes(classify(round_trip(parts::cell_target(target_size), "target")), parts::cell_target_holes());
}

// What classify() finds in a file rigger did not make. The face counts by type agree with the file's own
// entities (screw.step: 10 ADVANCED_FACE, 4 PLANE, 1 CYLINDRICAL_SURFACE; linkrods.step: 37, 6, 4), plus
// linkrods.step's four B-spline fillets of 0.125 mm radius, cylinders within 0.01 mm and 1e-3 rad.
struct Counts {
  int solids;
  std::size_t faces, edges, vertices;
  int planes, cylinders;
  std::size_t holes;
};

void expect_counts(const Features& features, const Counts& want) {
  EXPECT_EQ(features.solids, want.solids);
  EXPECT_EQ(features.faces.size(), want.faces);
  EXPECT_EQ(features.edges.size(), want.edges);
  EXPECT_EQ(features.vertices.size(), want.vertices);
  EXPECT_EQ(features.count_faces("plane"), want.planes);
  EXPECT_EQ(features.count_faces("cylinder"), want.cylinders);
  EXPECT_EQ(features.holes.size(), want.holes);
}

TEST_F(CadTest, ScrewStepFromOcctSamples) {
  const Model model = read_step_file(kOcctSamples / "screw.step");
  EXPECT_EQ(model.sha256().size(), 64u);
  expect_counts(classify(model), {1, 10, 22, 14, 4, 1, 0});
}

TEST_F(CadTest, LinkrodsStepFromOcctSamples) {
  const Model model = read_step_file(kOcctSamples / "linkrods.step");
  const Features features = classify(model);
  expect_counts(features, {1, 37, 108, 74, 6, 8, 2});
  int fillets = 0;
  for (const auto& face : features.faces) {
    if (face.recognised) {
      ++fillets;
      EXPECT_EQ(face.signature.type, "cylinder") << "face " << face.index;
      EXPECT_NEAR(face.signature.radius_m, 0.000125, 1e-6) << "face " << face.index;
    }
  }
  EXPECT_EQ(fillets, 4);
  EXPECT_EQ(model.product().children.size(), 0u);
  for (const auto& hole : features.holes) {
    EXPECT_GT(hole.diameter_m, 0.0);
    EXPECT_GT(hole.depth_m, 0.0);
    EXPECT_NEAR(hole.axis.norm(), 1.0, 1e-12);
  }
}


TEST_F(CadTest, ProductNamesComeFromTheStepFile) {
  const Model model = read_step_file(kOcctSamples / "screw.step");
  EXPECT_FALSE(model.product().name.empty());
  EXPECT_FALSE(model.product().assembly);
}

TEST_F(CadTest, BadInputGivesAClearError) {
  const auto code_of = [](const fs::path& path, const ReadLimits& limits = {}) {
    try {
      read_step_file(path, limits);
    } catch (const CadError& error) {
      EXPECT_NE(std::string(error.what()).find(path.string()), std::string::npos) << error.what();
      return error.code();
    }
    ADD_FAILURE() << path << " was read";
    return ErrorCode::kBadReference;
  };
  EXPECT_EQ(code_of(dir_ / "missing.step"), ErrorCode::kFileNotFound);
  EXPECT_EQ(code_of(write_text("empty.step", "")), ErrorCode::kEmpty);
  EXPECT_EQ(code_of(write_text("junk.step", std::string("\x7f" "ELF\x02\x01\x01\0\0\xff\xfe", 12))), ErrorCode::kNotStep);
  EXPECT_EQ(code_of(write_text("text.step", "hello, this is not STEP\n")), ErrorCode::kNotStep);
  // Truncated: the first 40% of a real file.
  std::ifstream in(kOcctSamples / "screw.step", std::ios::binary);
  const std::string screw((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const ErrorCode truncated = code_of(write_text("truncated.step", screw.substr(0, screw.size() * 2 / 5)));
  EXPECT_TRUE(truncated == ErrorCode::kNotStep || truncated == ErrorCode::kNoGeometry) << to_string(truncated);
  // Without a length unit (the representation context's unit assignment cut out), or with the angle
  // unit alone: the numbers could be anything.
  const std::string units = "GLOBAL_UNIT_ASSIGNED_CONTEXT((#1237,#1238)) ";
  ASSERT_NE(screw.find(units), std::string::npos);
  std::string unitless = screw;
  unitless.replace(unitless.find(units), units.size(), "");
  EXPECT_EQ(code_of(write_text("unitless.step", unitless)), ErrorCode::kNoUnits);
  std::string angle_only = screw;
  const std::string angle_unit = units.substr(units.find(',') + 1, units.find(')') - units.find(',') - 1);
  angle_only.replace(angle_only.find(units), units.size(), "GLOBAL_UNIT_ASSIGNED_CONTEXT((" + angle_unit + ")) ");
  EXPECT_EQ(code_of(write_text("angle_only.step", angle_only)), ErrorCode::kNoUnits);
  // A header and no data.
  EXPECT_EQ(code_of(write_text("nodata.step", screw.substr(0, screw.find("DATA;") + 5) + "\nENDSEC;\nEND-ISO-10303-21;\n")),
            ErrorCode::kNotStep);
  // 200 MB (sparse): refused by its size before anything is read.
  const fs::path huge = dir_ / "huge.step";
  std::ofstream(huge).close();
  fs::resize_file(huge, 200ull << 20);
  EXPECT_EQ(code_of(huge), ErrorCode::kTooLarge);
  // The same bounds apply to bytes.
  EXPECT_THROW(read_step_bytes(screw, "bytes", ReadLimits{1000}), CadError);
}

TEST_F(CadTest, DeeplyNestedAssemblyIsRefused) {
  Handle(TDocStd_Document) document;
  XCAFApp_Application::GetApplication()->NewDocument("MDTV-XCAF", document);
  XCAFDoc_DocumentTool::SetLengthUnit(document, 1.0);
  Handle(XCAFDoc_ShapeTool) shapes = XCAFDoc_DocumentTool::ShapeTool(document->Main());
  TDF_Label child = shapes->AddShape(BRepPrimAPI_MakeBox(0.01, 0.01, 0.01).Shape(), false);
  for (int depth = 0; depth < 40; ++depth) {
    const TDF_Label assembly = shapes->NewShape();
    shapes->AddComponent(assembly, child, TopLoc_Location());
    child = assembly;
  }
  shapes->UpdateAssemblies();
  STEPCAFControl_Writer writer;
  ASSERT_TRUE(writer.Transfer(document, STEPControl_AsIs));
  const fs::path path = dir_ / "nested.step";
  ASSERT_EQ(writer.Write(path.c_str()), IFSelect_RetDone);
  try {
    read_step_file(path);
    FAIL() << "a 40-level assembly was read";
  } catch (const CadError& error) {
    EXPECT_EQ(error.code(), ErrorCode::kTooDeep) << error.what();
  }
  ReadLimits deep;
  deep.max_assembly_depth = 64;
  const Model model = read_step_file(path, deep);
  EXPECT_TRUE(model.product().assembly);
}

TEST_F(CadTest, ReaderChildIsBoundedInTimeAndMemory) {
  ReadLimits quick;
  quick.timeout = std::chrono::milliseconds(1);
  try {
    read_step_file(kOcctSamples / "linkrods.step", quick);
    FAIL() << "read within 1 ms";
  } catch (const CadError& error) {
    EXPECT_EQ(error.code(), ErrorCode::kTimeout) << error.what();
  }
  ReadLimits small;
  small.max_memory_bytes = 32ull << 20;
  try {
    read_step_file(kOcctSamples / "linkrods.step", small);
    FAIL() << "read within 32 MiB";
  } catch (const CadError& error) {
    EXPECT_EQ(error.code(), ErrorCode::kCrashed) << error.what();
  }
  // This process is untouched: the same file reads normally afterwards.
  EXPECT_EQ(classify(read_step_file(kOcctSamples / "linkrods.step")).faces.size(), 37u);
}

// A STEP file on which OCCT 7.6's reader dereferences a null pointer (StepShape_FaceBound::Bound, found by
// rigger_cad_step_fuzz): the reader child dies, the caller gets CAD_READER_CRASHED and goes on.
TEST_F(CadTest, OcctCrashInTheReaderIsContained) {
  const fs::path hostile = fs::path(RIGGER_SOURCE_DIR) / "common/cad/test/data/occt_segv_face_bound.step";
  try {
    read_step_file(hostile);
    FAIL() << "the hostile file was read";
  } catch (const CadError& error) {
    EXPECT_EQ(error.code(), ErrorCode::kCrashed) << error.what();
    EXPECT_NE(std::string(error.what()).find("signal 11"), std::string::npos) << error.what();
  }
  EXPECT_EQ(classify(read_step_file(kOcctSamples / "screw.step")).faces.size(), 10u);
}

TEST_F(CadTest, InProcessAndIsolatedReadsAgree) {
  ReadLimits in_process;
  in_process.isolate = false;
  const Features a = classify(read_step_file(kOcctSamples / "linkrods.step", in_process));
  const Features b = classify(read_step_file(kOcctSamples / "linkrods.step"));
  ASSERT_EQ(a.faces.size(), b.faces.size());
  EXPECT_EQ(a.model_sha256, b.model_sha256);
  for (std::size_t i = 0; i < a.faces.size(); ++i) {
    EXPECT_TRUE(same_signature(a.faces[i].signature, b.faces[i].signature, 1e-12, 1e-12)) << i;
  }
}

// B-spline faces get their centroids from an adaptive integral (1e-3 relative on the area) instead of
// OCCT's fixed-order one, which took most of classify(): on linkrods.step (29 non-planar faces, 18 of
// them B-spline) the two agree within 1e-7 m, a tenth of the signature tolerance, and every face still
// has a signature no other face matches, so a reference found by its signature alone finds its face.
TEST_F(CadTest, FreeformCentroidsAreCheapButStillTellFacesApart) {
  const Model model = read_step_file(kOcctSamples / "linkrods.step");
  const Features features = classify(model);
  TopTools_IndexedMapOfShape faces;
  TopExp::MapShapes(model.shape(), TopAbs_FACE, faces);
  ASSERT_EQ(static_cast<std::size_t>(faces.Extent()), features.faces.size());
  int freeform = 0;
  for (int i = 1; i <= faces.Extent(); ++i) {
    const auto& face = features.faces[static_cast<std::size_t>(i - 1)];
    if (face.signature.type != "bspline") {
      continue;
    }
    ++freeform;
    GProp_GProps fixed_order;
    BRepGProp::SurfaceProperties(faces(i), fixed_order);
    const gp_Pnt centroid = fixed_order.CentreOfMass();
    EXPECT_LT((face.signature.centroid_m - Eigen::Vector3d(centroid.X(), centroid.Y(), centroid.Z())).norm(), 1e-7)
        << "face " << i - 1;
    EXPECT_NEAR(face.area_m2, fixed_order.Mass(), 3e-3 * fixed_order.Mass()) << "face " << i - 1;
  }
  EXPECT_EQ(freeform, 14);  // 18 B-spline faces, of which 4 are cylindrical fillets
  for (std::size_t i = 0; i < features.faces.size(); ++i) {
    EXPECT_EQ(resolve(features, features.reference(EntityKind::kFace, static_cast<int>(i))), static_cast<int>(i));
    Reference elsewhere = features.reference(EntityKind::kFace, static_cast<int>(i));
    elsewhere.index = -1;  // found by its signature alone: exactly one face has it
    EXPECT_EQ(resolve(features, elsewhere), static_cast<int>(i));
  }
}

TEST_F(CadTest, ReferencesSurviveTheSameModelAndGoStaleOnAnEdit) {
  const Features original = classify(round_trip(parts::plate(), "plate"));
  // The same geometry written again: same signatures, so every reference resolves to its index.
  const Features again = classify(round_trip(parts::plate(), "plate_again"));
  for (std::size_t i = 0; i < original.faces.size(); ++i) {
    EXPECT_EQ(resolve(again, original.reference(EntityKind::kFace, static_cast<int>(i))), static_cast<int>(i));
  }
  // Move the first hole by 5 mm: its wall's reference is stale, the top face's too (its centroid
  // moved), a far side face still resolves.
  auto holes = parts::plate_holes();
  holes[0].entry_m.x() += 0.005;
  const Features edited = classify(round_trip(parts::drilled_box({0, 0, 0}, {0.2, 0.1, 0.01}, holes), "edited"));
  const int wall = original.holes[0].faces.front();
  try {
    resolve(edited, original.reference(EntityKind::kFace, wall));
    FAIL() << "a moved hole's wall resolved";
  } catch (const CadError& error) {
    EXPECT_EQ(error.code(), ErrorCode::kStaleReference) << error.what();
  }
  int side = -1;
  for (const auto& face : original.faces) {
    if (face.signature.type == "plane" && face.normal.isApprox(Eigen::Vector3d::UnitX(), 1e-9)) {
      side = face.index;
    }
  }
  ASSERT_GE(side, 0);
  const int now = resolve(edited, original.reference(EntityKind::kFace, side));
  EXPECT_TRUE(edited.faces[static_cast<std::size_t>(now)].normal.isApprox(Eigen::Vector3d::UnitX(), 1e-9));
  EXPECT_THROW(original.reference(EntityKind::kEdge, 100000), CadError);
  // A reference survives a JSON round trip.
  const Reference ref = original.reference(EntityKind::kFace, side);
  EXPECT_EQ(resolve(original, reference_from_json(to_json(ref))), side);
}

TEST_F(CadTest, FramesFromEdgesFaceAndHole) {
  const Model model = round_trip(parts::block(), "block");
  const Features features = classify(model);
  // The block's corner at the origin: the edges along x and y that start or end there.
  int along_x = -1, along_y = -1;
  for (const auto& edge : features.edges) {
    if (edge.signature.type != "line" || (edge.start_m.norm() > 1e-9 && edge.end_m.norm() > 1e-9)) {
      continue;
    }
    const Eigen::Vector3d d = edge.signature.direction;
    if (d.isApprox(Eigen::Vector3d::UnitX(), 1e-9)) along_x = edge.index;
    if (d.isApprox(Eigen::Vector3d::UnitY(), 1e-9)) along_y = edge.index;
  }
  ASSERT_GE(along_x, 0);
  ASSERT_GE(along_y, 0);
  const Eigen::Isometry3d frame = frame_from_edges(features, {0.01, 0.02, 0.03}, along_x, along_y);
  EXPECT_LT((frame.translation() - Eigen::Vector3d(0.01, 0.02, 0.03)).norm(), kTolM);
  EXPECT_NEAR(std::abs(frame.linear().col(2).z()), 1.0, kTolRad);
  EXPECT_NEAR(frame.linear().determinant(), 1.0, 1e-12);
  EXPECT_THROW(frame_from_edges(features, {0, 0, 0}, along_x, along_x), CadError);
  // A circular edge gives no direction.
  int circle = -1;
  for (const auto& edge : features.edges) {
    if (edge.signature.type == "circle") circle = edge.index;
  }
  try {
    frame_from_edges(features, {0, 0, 0}, along_x, circle);
    FAIL();
  } catch (const CadError& error) {
    EXPECT_EQ(error.code(), ErrorCode::kNotAFrame);
    EXPECT_NE(std::string(error.what()).find("circle"), std::string::npos) << error.what();
  }

  // The top face (normal +z) at a picked point.
  int top = -1;
  for (const auto& face : features.faces) {
    // (the blind hole's bottom faces +z too, 20 mm lower)
    if (face.signature.type == "plane" && face.normal.isApprox(Eigen::Vector3d::UnitZ(), 1e-9) &&
        face.signature.centroid_m.z() > 0.05 - 1e-9) {
      top = face.index;
    }
  }
  ASSERT_GE(top, 0);
  const Eigen::Isometry3d on_top = frame_from_face(model, features, top, {0.05, 0.01, 0.0501});
  EXPECT_LT((on_top.translation() - Eigen::Vector3d(0.05, 0.01, 0.05)).norm(), kTolM);
  EXPECT_LT((on_top.linear().col(2) - Eigen::Vector3d::UnitZ()).norm(), kTolRad);
  try {
    frame_from_face(model, features, top, {0.05, 0.01, 0.06});
    FAIL() << "a point 10 mm above the face made a frame";
  } catch (const CadError& error) {
    EXPECT_EQ(error.code(), ErrorCode::kNotAFrame);
    EXPECT_NE(std::string(error.what()).find("10 mm"), std::string::npos) << error.what();
  }
  try {
    frame_from_face(model, features, top, {0.03, 0.04, 0.05});  // in the through hole's opening
    FAIL() << "a point in a hole's opening made a frame";
  } catch (const CadError& error) {
    EXPECT_NE(std::string(error.what()).find("outside its boundary"), std::string::npos) << error.what();
  }
  // The side blind hole: z along +x (out of the hole), origin at its entry.
  for (const auto& hole : features.holes) {
    const Eigen::Isometry3d h = frame_from_hole(features, hole.index);
    EXPECT_LT((h.translation() - hole.entry_m).norm(), kTolM);
    EXPECT_LT((h.linear().col(2) - hole.axis).norm(), kTolRad);
  }
  EXPECT_THROW(frame_from_hole(features, 3), CadError);
}

// An L of two boxes (a 0.4 x 0.3 x 0.03 m plate and a 0.03 x 0.3 x 0.3 m web on its -x edge): the sling's ring
// 20 mm above the web, over the centre of mass (x = 0.0027 * -0.185 / 0.0063 = -0.07929 m).
TEST_F(CadTest, TheSlingFrameIsAboveTheCentreOfMass) {
  TopoDS_Compound l_shape;
  BRep_Builder builder;
  builder.MakeCompound(l_shape);
  builder.Add(l_shape, BRepPrimAPI_MakeBox(gp_Pnt(-0.2, -0.15, 0.0), gp_Pnt(0.2, 0.15, 0.03)).Shape());
  builder.Add(l_shape, BRepPrimAPI_MakeBox(gp_Pnt(-0.2, -0.15, 0.03), gp_Pnt(-0.17, 0.15, 0.33)).Shape());
  const Model model = round_trip(l_shape, "l_bracket");
  const Eigen::Isometry3d sling = frame_above_centre_of_mass(model, 0.02);
  EXPECT_LT((sling.translation() - Eigen::Vector3d(-0.0027 * 0.185 / 0.0063, 0.0, 0.35)).norm(), 1e-6)
      << sling.translation().transpose();
  EXPECT_TRUE(sling.linear().isIdentity(1e-12));
  // A face alone has no volume: no centre of mass.
  TopExp_Explorer faces(l_shape, TopAbs_FACE);
  try {
    frame_above_centre_of_mass(Model(faces.Current(), {}, "face", "in memory"), 0.02);
    FAIL() << "a face was given a centre of mass";
  } catch (const CadError& error) {
    EXPECT_EQ(error.code(), ErrorCode::kNotAFrame);
    EXPECT_NE(std::string(error.what()).find("no volume"), std::string::npos) << error.what();
  }
}

TEST_F(CadTest, TessellationIsGlbInMetresWithOnePrimitivePerFace) {
  const Model model = round_trip(parts::cell_load({0.40, 0.30, 0.20}), "load");
  const Features features = classify(model);
  const Tessellation mesh = tessellate(model);
  ASSERT_GT(mesh.glb.size(), 20u);
  EXPECT_EQ(std::string(mesh.glb.begin(), mesh.glb.begin() + 4), "glTF");
  EXPECT_EQ(mesh.primitive_face.size(), features.faces.size());
  EXPECT_GT(mesh.triangles, 12u);
  // The JSON chunk: one mesh with a primitive per face, positions within the box (metres, z up).
  std::uint32_t json_length = 0;
  std::memcpy(&json_length, mesh.glb.data() + 12, 4);
  const auto gltf = nlohmann::json::parse(mesh.glb.begin() + 20, mesh.glb.begin() + 20 + json_length);
  ASSERT_EQ(gltf["meshes"].size(), 1u);
  ASSERT_EQ(gltf["meshes"][0]["primitives"].size(), mesh.primitive_face.size());
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(1e9), hi = Eigen::Vector3d::Constant(-1e9);
  for (const auto& primitive : gltf["meshes"][0]["primitives"]) {
    const auto& accessor = gltf["accessors"][primitive["attributes"]["POSITION"].get<int>()];
    for (int i = 0; i < 3; ++i) {
      lo[i] = std::min(lo[i], accessor["min"][i].get<double>());
      hi[i] = std::max(hi[i], accessor["max"][i].get<double>());
    }
  }
  EXPECT_LT((lo - Eigen::Vector3d(-0.20, -0.15, -0.10)).norm(), 1e-6) << lo.transpose();
  EXPECT_LT((hi - Eigen::Vector3d(0.20, 0.15, 0.10)).norm(), 1e-6) << hi.transpose();
  const auto json = tessellation_json(features, mesh);
  EXPECT_EQ(json["parts"].size(), features.faces.size());
  EXPECT_EQ(json["parts"][3]["face"], mesh.primitive_face[3]);
}

TEST(SolidProblem, ClosedSolidsPassAFaceOrAnOpenShellDoesNot) {
  const TopoDS_Shape box = BRepPrimAPI_MakeBox(0.4, 0.3, 0.2).Shape();
  EXPECT_EQ(solid_problem(model_from_shape(box, "box")), "");
  TopExp_Explorer faces(box, TopAbs_FACE);
  EXPECT_EQ(solid_problem(model_from_shape(faces.Current(), "face")), "no solid (faces or shells only)");
  // The box's shell without its last face, made a solid: open.
  TopoDS_Shell open;
  BRep_Builder builder;
  builder.MakeShell(open);
  int count = 0;
  for (TopExp_Explorer f(box, TopAbs_FACE); f.More(); f.Next()) {
    if (++count < 6) builder.Add(open, f.Current());
  }
  const TopoDS_Solid solid = BRepBuilderAPI_MakeSolid(open).Solid();
  EXPECT_EQ(solid_problem(model_from_shape(solid, "open")), "solid 0 is not closed (or not a valid solid)");
}

}  // namespace
}  // namespace rigger::cad
