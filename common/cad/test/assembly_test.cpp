// A node of an assembly as a STEP file of its own: an assembly written with OpenCascade here (two
// sub-assemblies, one of two parts, the other one part used twice), its nodes extracted and read back
// through the normal reader.

#include "rigger/cad/assembly.hpp"
#include "rigger/cad/features.hpp"
#include "rigger/cad/parts.hpp"
#include "step_file_test.hpp"

#include <BRepBndLib.hxx>
#include <BRepPrimAPI_MakeBox.hxx>
#include <Bnd_Box.hxx>
#include <gtest/gtest.h>

#include <algorithm>
#include <vector>

namespace rigger::cad {
namespace {

namespace fs = std::filesystem;
using AssemblyTest = StepFileTest;

struct Box {
  Eigen::Vector3d min, max;
};

Box bounds(const Model& model) {
  Bnd_Box box;
  BRepBndLib::AddOptimal(model.shape(), box, false, false);
  double x0, y0, z0, x1, y1, z1;
  box.Get(x0, y0, z0, x1, y1, z1);
  return {{x0, y0, z0}, {x1, y1, z1}};
}

void expect_box(const Box& box, const Eigen::Vector3d& min, const Eigen::Vector3d& max) {
  EXPECT_LT((box.min - min).norm(), 1e-6) << box.min.transpose() << " (expected " << min.transpose() << ")";
  EXPECT_LT((box.max - max).norm(), 1e-6) << box.max.transpose() << " (expected " << max.transpose() << ")";
}

std::string file_text(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

// The error `extract` throws: its code, with the message kept for the checks.
ErrorCode refusal(const std::string& bytes, const NodePath& path, std::string& message) {
  try {
    extract_step_node(bytes, "assembly.step", path);
  } catch (const CadError& error) {
    message = error.what();
    return error.code();
  }
  ADD_FAILURE() << "node " << to_string(path) << " was extracted";
  return ErrorCode::kCrashed;
}

TEST_F(AssemblyTest, TheProductTreeNamesEachProductAndInstance) {
  const fs::path file = dir_ / "assembly.step";
  write_step_assembly(parts::test_assembly(), file);
  const Model model = read_step_file(file);
  const ProductNode& root = model.product();
  EXPECT_EQ(root.name, "cell_assembly");
  ASSERT_EQ(root.children.size(), 2u);
  EXPECT_EQ(root.children[0].name, "frame");
  EXPECT_EQ(root.children[0].instance, "frame_1");
  ASSERT_EQ(root.children[0].children.size(), 2u);
  EXPECT_EQ(root.children[0].children[0].name, "plate");
  EXPECT_EQ(root.children[0].children[1].instance, "bracket_1");
  const ProductNode& pair = root.children[1];
  ASSERT_EQ(pair.children.size(), 2u);
  EXPECT_EQ(pair.children[0].name, "block");
  EXPECT_EQ(pair.children[1].name, "block");
  EXPECT_EQ(pair.children[0].instance, "block_left");
  EXPECT_EQ(pair.children[1].instance, "block_right");
}

TEST_F(AssemblyTest, ANodeIsItsOwnStepFileInItsOwnFrameWithItsNamesAndUnit) {
  const fs::path file = dir_ / "assembly.step";
  write_step_assembly(parts::test_assembly(), file);
  const std::string bytes = file_text(file);

  // The sub-assembly of two parts: both solids, the plate's three holes and the bracket's two, in the
  // frame's own frame (not where the file puts it), its names kept.
  const ExtractedNode frame = extract_step_node(bytes, "assembly.step", {0});
  EXPECT_EQ(frame.name, "frame");
  EXPECT_EQ(frame.instance, "frame_1");
  EXPECT_LT((frame.pose_in_file.translation() - Eigen::Vector3d(1.0, 0, 0)).norm(), 1e-9);
  const Model frame_model = read_step_bytes(frame.step, "frame.step");
  const Features frame_features = classify(frame_model);
  EXPECT_EQ(frame_features.solids, 2);
  EXPECT_EQ(frame_features.holes.size(), 5u);
  expect_box(bounds(frame_model), {0, 0, 0}, {0.3, 0.2, 0.06});
  EXPECT_EQ(frame_model.product().name, "frame");
  ASSERT_EQ(frame_model.product().children.size(), 2u);
  EXPECT_EQ(frame_model.product().children[0].name, "plate");
  EXPECT_EQ(frame_model.product().children[0].instance, "plate_1");
  EXPECT_EQ(frame_model.product().children[1].instance, "bracket_1");
  EXPECT_NE(frame.step.find("SI_UNIT(.MILLI.,.METRE.)"), std::string::npos) << "the file's millimetres";
  EXPECT_EQ(frame.step.find("CONVERSION_BASED_UNIT"), std::string::npos);

  // The same node of the same file: the same bytes, isolated or not, whatever was written before.
  const std::string sha = sha256_hex(frame.step);
  EXPECT_EQ(sha256_hex(extract_step_node(bytes, "again.step", {0}).step), sha);
  ReadLimits in_process;
  in_process.isolate = false;
  EXPECT_EQ(sha256_hex(extract_step_node(bytes, "assembly.step", {0}, in_process).step), sha);
  write_step_assembly(parts::test_assembly(), dir_ / "again.step");
  EXPECT_EQ(sha256_hex(extract_step_node(bytes, "assembly.step", {0}, in_process).step), sha);
  EXPECT_EQ(sha256_hex(extract_step_node(file, {0}).step), sha);

  // One part of it: the plate alone, in its own frame; where the file has it is plate_1's pose in frame_1's.
  const ExtractedNode plate = extract_step_node(bytes, "assembly.step", {0, 0});
  EXPECT_EQ(plate.name, "plate");
  const Model plate_model = read_step_bytes(plate.step, "plate.step");
  EXPECT_EQ(classify(plate_model).holes.size(), 3u);
  expect_box(bounds(plate_model), {0, 0, 0}, {0.2, 0.1, 0.01});
  const Eigen::Isometry3d plate_in_file = parts::test_assembly_pose("frame_1") * parts::test_assembly_pose("plate_1");
  EXPECT_LT((plate.pose_in_file.matrix() - plate_in_file.matrix()).norm(), 1e-9) << plate.pose_in_file.matrix();

  // The part used twice: two nodes of one product, the same shape in its own frame, placed apart.
  const ExtractedNode left = extract_step_node(bytes, "assembly.step", {1, 0});
  const ExtractedNode right = extract_step_node(bytes, "assembly.step", {1, 1});
  EXPECT_EQ(left.instance, "block_left");
  EXPECT_EQ(right.instance, "block_right");
  EXPECT_EQ(sha256_hex(left.step), sha256_hex(right.step));
  const Eigen::Vector3d apart = right.pose_in_file.translation() - left.pose_in_file.translation();
  EXPECT_LT((apart - parts::test_assembly_pose("pair_1").linear() * Eigen::Vector3d(0.2, 0, 0)).norm(), 1e-9)
      << apart.transpose();
  const Model block = read_step_bytes(right.step, "block.step");
  EXPECT_EQ(classify(block).holes.size(), 3u);
  expect_box(bounds(block), {0, 0, 0}, {0.1, 0.08, 0.05});

  // The root: the whole assembly, 2 + 2 solids.
  EXPECT_EQ(classify(read_step_bytes(extract_step_node(bytes, "assembly.step", {}).step, "root.step")).solids, 4);
}

TEST_F(AssemblyTest, AFileInInchesGivesNodesInInches) {
  const fs::path file = dir_ / "inches.step";
  write_step_assembly(parts::test_assembly(), file, "INCH");
  ASSERT_NE(file_text(file).find("CONVERSION_BASED_UNIT('INCH'"), std::string::npos);
  expect_box(bounds(read_step_file(file)), {-0.08, 0, 0}, {1.3, 1.3, 0.06});
  const ExtractedNode frame = extract_step_node(file, {0});
  EXPECT_NE(frame.step.find("CONVERSION_BASED_UNIT('INCH'"), std::string::npos) << "the file's inches";
  expect_box(bounds(read_step_bytes(frame.step, "frame.step")), {0, 0, 0}, {0.3, 0.2, 0.06});
  EXPECT_LT((frame.pose_in_file.translation() - Eigen::Vector3d(1.0, 0, 0)).norm(), 1e-9);
}

TEST_F(AssemblyTest, ANodeThatDoesNotExistOrHoldsNoSolidIsRefusedSayingWhere) {
  const fs::path file = dir_ / "assembly.step";
  write_step_assembly(parts::test_assembly_with_a_sheet(), file);  // node 2: a sheet (one face, no solid)
  const std::string bytes = file_text(file);
  std::string message;
  EXPECT_EQ(refusal(bytes, {3}, message), ErrorCode::kBadReference);
  EXPECT_NE(message.find("no node 3: the root ('cell_assembly') has 3 components (0 to 2)"), std::string::npos) << message;
  EXPECT_EQ(refusal(bytes, {1, 2}, message), ErrorCode::kBadReference);
  EXPECT_NE(message.find("node 1 ('pair') has 2 components"), std::string::npos) << message;
  EXPECT_EQ(refusal(bytes, {0, 1, 0}, message), ErrorCode::kBadReference);
  EXPECT_NE(message.find("node 0/1 ('bracket') is a part, without components"), std::string::npos) << message;
  EXPECT_EQ(refusal(bytes, {-1}, message), ErrorCode::kBadReference);
  EXPECT_EQ(refusal(bytes, {2}, message), ErrorCode::kNoGeometry);
  EXPECT_NE(message.find("node 2 ('sheet') holds no solid"), std::string::npos) << message;
  EXPECT_EQ(refusal(bytes, NodePath(33, 0), message), ErrorCode::kBadReference);
  EXPECT_NE(message.find("33 levels, more than the limit of 32"), std::string::npos) << message;
  EXPECT_EQ(refusal("not a STEP file", {0}, message), ErrorCode::kNotStep);
}

}  // namespace
}  // namespace rigger::cad
