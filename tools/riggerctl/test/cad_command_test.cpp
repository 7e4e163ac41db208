// `riggerctl cad` as a user runs it: the real binary on the cell's STEP files, on a part written as B-splines
// and on a bad file.

#include "rigger/cad/assembly.hpp"
#include "rigger/cad/model.hpp"
#include "rigger/cad/parts.hpp"

#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>
#include <BRepBuilderAPI_NurbsConvert.hxx>

#include <array>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>

namespace {

struct CtlRun {
  int exit_code = -1;
  std::string out;
};

CtlRun riggerctl(const std::string& args) {
  const char* bin = std::getenv("RIGGER_BIN_DIR");
  const std::string command =
      std::string(bin != nullptr ? bin : RIGGER_BINARY_DIR "/bin") + "/riggerctl " + args + " 2>&1";
  CtlRun run;
  FILE* pipe = ::popen(command.c_str(), "r");
  std::array<char, 4096> buffer{};
  while (std::fgets(buffer.data(), buffer.size(), pipe) != nullptr) {
    run.out += buffer.data();
  }
  const int status = ::pclose(pipe);
  run.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return run;
}

const std::string kModels = RIGGER_SOURCE_DIR "/deploy/cell/models/";

TEST(RiggerctlCad, InspectJsonListsTheTargetsFourBlindHoles) {
  const CtlRun run = riggerctl("cad inspect --json " + kModels + "target.step");
  ASSERT_EQ(run.exit_code, 0) << run.out;
  const auto json = nlohmann::json::parse(run.out);
  EXPECT_EQ(json["product"]["name"], "target");
  EXPECT_EQ(json["counts"]["holes"], 4);
  for (const auto& hole : json["holes"]) {
    EXPECT_NEAR(hole["diameter_m"].get<double>(), 0.0102, 1e-9);
    EXPECT_NEAR(hole["depth_m"].get<double>(), 0.030, 1e-9);
    EXPECT_FALSE(hole["through"].get<bool>());
    EXPECT_NEAR(std::abs(hole["entry_m"][0].get<double>()), 0.15, 1e-9);
  }
}

TEST(RiggerctlCad, FrameFromAHoleAndRefusalsWithReasons) {
  CtlRun run = riggerctl("cad frame --json " + kModels + "load.step --hole 0");
  ASSERT_EQ(run.exit_code, 0) << run.out;
  const auto json = nlohmann::json::parse(run.out);
  EXPECT_NEAR(json["frame"]["position_m"][2].get<double>(), 0.10, 1e-9);
  EXPECT_NEAR(json["frame"]["z"][2].get<double>(), 1.0, 1e-9);
  run = riggerctl("cad frame " + kModels + "load.step --face 0 --point 5,5,5");
  EXPECT_EQ(run.exit_code, 1);
  EXPECT_NE(run.out.find("CAD_NOT_A_FRAME"), std::string::npos) << run.out;
  run = riggerctl("cad frame " + kModels + "load.step --edges 1");
  EXPECT_EQ(run.exit_code, 2) << run.out;
  run = riggerctl("cad inspect /nonexistent.step");
  EXPECT_EQ(run.exit_code, 1);
  EXPECT_NE(run.out.find("CAD_FILE_NOT_FOUND"), std::string::npos) << run.out;
}

// The plate written as B-splines only: inspect finds its holes and says which faces and edges it took
// for planes, cylinders, lines and circles.
TEST(RiggerctlCad, InspectSaysWhatWasRecognisedFromBspline) {
  const std::string path =
      std::filesystem::temp_directory_path() / ("riggerctl_bspline_" + std::to_string(::getpid()) + ".step");
  rigger::cad::write_step(BRepBuilderAPI_NurbsConvert(rigger::cad::parts::plate(), true).Shape(), "plate", path);
  CtlRun run = riggerctl("cad inspect --json " + path);
  ASSERT_EQ(run.exit_code, 0) << run.out;
  const auto counts = nlohmann::json::parse(run.out)["counts"];
  EXPECT_EQ(counts["holes"], rigger::cad::parts::plate_holes().size());
  EXPECT_EQ(counts["faces_from_bspline"], counts["faces"]);
  EXPECT_EQ(counts["cylindrical_faces"], 3);
  EXPECT_EQ(counts["planar_faces"], 6);
  run = riggerctl("cad inspect " + path);
  EXPECT_NE(run.out.find("recognised from B-spline (within 0.01 mm):\n  cylinder faces (3):"), std::string::npos)
      << run.out;
  EXPECT_NE(run.out.find("  plane faces (6):"), std::string::npos) << run.out;
  std::filesystem::remove(path);
}

// An assembly: inspect shows each node's path, extract writes the node it names as a STEP file of its own
// (its product in its own frame), and refuses a bad path, a missing node and an existing output file.
TEST(RiggerctlCad, ExtractWritesTheNodeInspectShowsAndRefusesSayingWhat) {
  namespace fs = std::filesystem;
  const fs::path dir = fs::temp_directory_path() / ("riggerctl_extract_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  const std::string file = (dir / "assembly.step").string(), out = (dir / "pair.step").string();
  rigger::cad::write_step_assembly(rigger::cad::parts::test_assembly(), file);
  CtlRun run = riggerctl("cad inspect " + file);
  ASSERT_EQ(run.exit_code, 0) << run.out;
  EXPECT_NE(run.out.find("instance pair_1  [1]\n"), std::string::npos) << run.out;
  EXPECT_NE(run.out.find("instance block_right  [1/1]\n"), std::string::npos) << run.out;

  run = riggerctl("cad extract " + file + " --node 1 -o " + out);
  ASSERT_EQ(run.exit_code, 0) << run.out;
  EXPECT_NE(run.out.find("node 1 ('pair', instance pair_1)"), std::string::npos) << run.out;
  const rigger::cad::Model pair = rigger::cad::read_step_file(out);
  EXPECT_EQ(pair.product().name, "pair");
  ASSERT_EQ(pair.product().children.size(), 2u);
  EXPECT_EQ(pair.product().children[1].instance, "block_right");
  EXPECT_NE(run.out.find("placed in the file at (0, 1, 0) m"), std::string::npos) << run.out;

  const auto size = fs::file_size(out);
  run = riggerctl("cad extract " + file + " --node 0 -o " + out);
  EXPECT_EQ(run.exit_code, 2) << run.out;
  EXPECT_NE(run.out.find("exists: not overwritten"), std::string::npos) << run.out;
  EXPECT_EQ(fs::file_size(out), size) << "the existing file changed";
  run = riggerctl("cad extract " + file + " --node 0/x -o " + (dir / "a.step").string());
  EXPECT_EQ(run.exit_code, 2) << run.out;
  EXPECT_NE(run.out.find("--node must be the component indices from the root"), std::string::npos) << run.out;
  run = riggerctl("cad extract " + file + " --node 3 -o " + (dir / "b.step").string());
  EXPECT_EQ(run.exit_code, 1) << run.out;
  EXPECT_NE(run.out.find("CAD_BAD_REFERENCE"), std::string::npos) << run.out;
  EXPECT_NE(run.out.find("no node 3"), std::string::npos) << run.out;
  EXPECT_FALSE(fs::exists(dir / "b.step")) << "a refused node left a file";
  fs::remove_all(dir);
}

}  // namespace
