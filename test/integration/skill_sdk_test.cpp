// A skill written outside this repository, as an integrator writes one: the skill SDK is installed
// (`cmake --install --component sdk`) into a temporary prefix, examples/skill_plugin is configured with
// find_package(rigger) against that prefix alone and built, its own unit tests (the SDK's fakes) pass,
// and its executor process `nudge_skills` runs on the simulated cell with the real task controller:
// announced, a recipe with an out-of-range offset refused at validation naming the parameter, and the
// Nudge recipe run to SUCCEEDED with the physics arm's tool seen 5 cm up and back.
#include <stdlib.h>

#include <algorithm>
#include <filesystem>

#include "cell_sim_test_support.hpp"
#include "controller_test_support.hpp"
#include "rigger/protocol/robot.hpp"
#include "rigger/testing/process.hpp"

namespace rigger::testing::controller {
namespace {

namespace fs = std::filesystem;

class SkillSdkTest : public ControllerTest {
 protected:
  /// Installs the SDK and builds the example once for the suite: its result (the build's output on
  /// failure) in build_error_.
  static void SetUpTestSuite() {
    char pattern[] = "/tmp/rigger-sdk-test-XXXXXX";
    ASSERT_NE(::mkdtemp(pattern), nullptr);
    tmp_ = pattern;
    const std::string build_dir = fs::canonical(bin_dir() + "/..").string();
    const std::string script =
        "set -e; " + shell_quoted(RIGGER_CMAKE_COMMAND) + " --install " + shell_quoted(build_dir) +
        " --component sdk --prefix " + shell_quoted(tmp_ + "/prefix") + " >/dev/null && " +
        shell_quoted(RIGGER_CMAKE_COMMAND) + " -S " +
        shell_quoted(std::string(RIGGER_SOURCE_DIR) + "/examples/skill_plugin") + " -B " +
        shell_quoted(tmp_ + "/build") +
        " -G Ninja -DCMAKE_BUILD_TYPE=Release -DCMAKE_PREFIX_PATH=" + shell_quoted(tmp_ + "/prefix") + " && " +
        shell_quoted(RIGGER_CMAKE_COMMAND) + " --build " + shell_quoted(tmp_ + "/build") + " -j 2 && cd " +
        shell_quoted(tmp_ + "/build") + " && ctest --output-on-failure";
    ChildProcess p("/bin/bash", {"-c", script}, {}, tmp_ + "/build.log");
    auto st = p.wait(std::chrono::minutes(5));
    if (!st) {
      p.signal(SIGKILL);
      p.wait(std::chrono::seconds(5));
    }
    build_output_ = p.log();
    built_ = st && st->ok();
  }
  static void TearDownTestSuite() {
    std::error_code ec;
    fs::remove_all(tmp_, ec);
  }

  static std::string tmp_, build_output_;
  static bool built_;
};
std::string SkillSdkTest::tmp_, SkillSdkTest::build_output_;
bool SkillSdkTest::built_ = false;

// One test, so that the SDK is installed and the example built once (each test is its own process).
TEST_F(SkillSdkTest, AnOutOfTreeSkillBuiltAgainstTheInstalledSdkRunsInARecipeOnThePhysicsArm) {
  ASSERT_TRUE(built_) << build_output_;
  // Its CMake cache found rigger in the temporary prefix, not in this build tree, and its unit tests ran.
  std::ifstream cache(tmp_ + "/build/CMakeCache.txt");
  const std::string text((std::istreambuf_iterator<char>(cache)), std::istreambuf_iterator<char>());
  EXPECT_NE(text.find("rigger_DIR:PATH=" + tmp_ + "/prefix/lib/cmake/rigger"), std::string::npos);
  EXPECT_NE(build_output_.find("100% tests passed"), std::string::npos) << build_output_;

  std::vector<Eigen::Vector3d> tool;
  dds::Reader<rigger_robot_RobotState> robot(cell_.participant(), protocol::robot::kState);
  cell_.loop().on_data(robot, [&] {
    robot.take([&](const rigger_robot_RobotState& s, const dds_sample_info_t&) {
      tool.push_back(dds::to_domain(s.tool_pose).translation());
    });
  });
  const std::string plc_port = std::to_string(free_tcp_port());
  cell_.start("cell_sim", "cell_sim", {"--config", repo_file("deploy/config/cell_sim.json"), "--plc-port", plc_port});
  const json executor = {{"executor_id", "nudge-skills"}, {"gripper", false}, {"world_model", false},
                         {"crane", false},                {"tracker", false}, {"admittance", false},
                         {"operator", false}};
  cell_.start("nudge-skills", tmp_ + "/build/nudge_skills",
              {"--id", "nudge-skills", "--config", write_config("nudge-skills", executor)});
  start_controller();
  wait_ready({"cell_sim", "nudge-skills", "tc"});
  ASSERT_TRUE(cell_.wait_until([&] { return !tool.empty(); }, 10s)) << "no robot state from cell_sim";

  // Validated against what the executor announced: an offset beyond the declared ±0.2 m is refused.
  const auto nudge = [](const std::string& task_id, double dz) {
    return json{{"recipe_version", 1},
                {"task_id", task_id},
                {"root", {{"name", "nudge"}, {"type", "Skill"}, {"skill", "Nudge"}, {"params", {{"dz_m", dz}}}}}};
  };
  submit("too-far", nudge("too-far", 0.5));
  ASSERT_TRUE(wait_finished("too-far", 20s)) << cell_.logs();
  EXPECT_EQ(last("too-far").state, rigger_task_TASK_REJECTED) << last("too-far").message;
  EXPECT_NE(last("too-far").message.find("dz_m"), std::string::npos) << last("too-far").message;

  const Eigen::Vector3d start = tool.back();
  const std::size_t from = tool.size();
  submit("nudge", nudge("nudge", 0.05));
  ASSERT_TRUE(wait_finished("nudge", 60s)) << cell_.logs();
  EXPECT_EQ(last("nudge").state, rigger_task_TASK_SUCCEEDED) << last("nudge").code << ": " << last("nudge").message;
  double highest = -1.0;
  for (std::size_t i = from; i < tool.size(); ++i) highest = std::max(highest, tool[i].z() - start.z());
  EXPECT_NEAR(highest, 0.05, 0.003) << "the tool's highest point above its start";
  EXPECT_LT((tool.back() - start).norm(), 0.003) << "the tool did not come back";
}

}  // namespace
}  // namespace rigger::testing::controller
