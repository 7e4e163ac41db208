// `riggerctl cad` as a user runs it: the real binary on the cell's STEP files and on a bad file.

#include <gtest/gtest.h>
#include <sys/wait.h>

#include <array>
#include <cstdio>
#include <cstdlib>
#include <nlohmann/json.hpp>
#include <string>

namespace {

struct CtlRun {
  int exit_code = -1;
  std::string out;
};

CtlRun riggerctl(const std::string& args) {
  const char* bin = std::getenv("RIGGER_BIN_DIR");
  const std::string command = std::string(bin != nullptr ? bin : RIGGER_BINARY_DIR "/bin") + "/riggerctl " + args + " 2>&1";
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

}  // namespace
