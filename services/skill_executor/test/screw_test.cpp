// Screw's FSM on fakes: hole look-up (world model features and positions, overrides), one prompt per
// hole withdrawn whenever it is left, every answer, timeouts, bad params and shutdown from every state.
#include <gtest/gtest.h>

#include "run_steps.hpp"
#include "sdk_testing.hpp"
#include "skills/screw.hpp"

namespace rigger::skill_executor {
namespace {

using namespace std::chrono_literals;
using testing::RunHarness;

nlohmann::json target_features() {
  return {{"screw_holes",
           {{{"id", "h1"}, {"screw_type", "M12x40"}, {"torque_nm", 60.0}},
            {{"id", "h2"}, {"screw_type", "M10x30"}, {"torque_nm", 45.0}}}}};
}

Eigen::Isometry3d at(double x, double y, double z) {
  Eigen::Isometry3d p = Eigen::Isometry3d::Identity();
  p.translation() = Eigen::Vector3d(x, y, z);
  return p;
}

class ScrewTest : public ::testing::Test {
 protected:
  SkillType type_{ScrewSkill::describe(), [] { return std::make_unique<ScrewSkill>(); }};
  nlohmann::json params_ = {{"holes", {"target/h1", "target/h2"}}, {"timeout_per_hole_s", 60.0}};

  /// Starts and answers the look-up: features of "target", then the two positions.
  void look_up(RunHarness& h) {
    h.run->start();
    ASSERT_EQ(h.state(), "lookup");
    ASSERT_EQ(h.world.features_entity(), "target");
    ASSERT_TRUE(h.world.answer_features(OpResult::success(), target_features()));
    ASSERT_NE(h.resolver.oldest(), nullptr);
    EXPECT_EQ(h.resolver.oldest()->ref, "target/h1");
    EXPECT_EQ(h.resolver.oldest()->frame, "world");
    ASSERT_TRUE(h.resolver.answer(OpResult::success(), at(1.0, 2.0, 0.3)));
    EXPECT_EQ(h.world.features_entity(), "") << "one features query per entity";
    ASSERT_TRUE(h.resolver.answer(OpResult::success(), at(1.1, 2.0, 0.3)));
    ASSERT_EQ(h.state(), "prompt");
  }
};

TEST_F(ScrewTest, SuccessPromptsEveryHoleWithItsDataAndWithdrawsEachPrompt) {
  RunHarness h(type_, params_);
  look_up(h);
  const auto* first = h.operator_panel.newest();
  ASSERT_NE(first, nullptr);
  EXPECT_EQ(first->spec.kind, "screw");
  EXPECT_EQ(first->spec.options, (std::vector<std::string>{"done", "failed", "abort"}));
  EXPECT_EQ(first->spec.details["hole"], "h1");
  EXPECT_EQ(first->spec.details["screw_type"], "M12x40");
  EXPECT_DOUBLE_EQ(first->spec.details["torque_nm"].get<double>(), 60.0);
  EXPECT_DOUBLE_EQ(first->spec.details["position_m"][0].get<double>(), 1.0);
  EXPECT_DOUBLE_EQ(first->spec.timeout_s, 60.0);
  ASSERT_TRUE(h.operator_panel.answer("done"));
  EXPECT_EQ(h.operator_panel.active(), 1u) << "the first prompt is withdrawn, the second is up";
  const auto* second = h.operator_panel.newest();
  EXPECT_EQ(second->spec.details["hole"], "h2");
  EXPECT_EQ(second->spec.details["screw_type"], "M10x30");
  EXPECT_DOUBLE_EQ(second->spec.details["torque_nm"].get<double>(), 45.0);
  EXPECT_FALSE(h.result);
  ASSERT_TRUE(h.operator_panel.answer("done"));
  ASSERT_TRUE(h.succeeded());
  EXPECT_EQ(h.operator_panel.active(), 0u);
  EXPECT_EQ(h.operator_panel.prompts.size(), 2u);
  // Progress per hole, increasing, ending at 1.
  ASSERT_GE(h.progress.size(), 3u);
  EXPECT_DOUBLE_EQ(h.progress.back().first, 1.0);
  EXPECT_EQ(h.timers.pending(), 0u);
}

TEST_F(ScrewTest, ParamsOverrideTheWorldModelsTypeAndTorque) {
  params_["torque_nm"] = 80.0;
  params_["screw_type"] = "M16x50";
  RunHarness h(type_, params_);
  look_up(h);
  EXPECT_EQ(h.operator_panel.newest()->spec.details["screw_type"], "M16x50");
  EXPECT_DOUBLE_EQ(h.operator_panel.newest()->spec.details["torque_nm"].get<double>(), 80.0);
}

// Per hole from the recipe: the hole's own value, else the one for every hole, else the world model's.
TEST_F(ScrewTest, PerHoleValuesComeBeforeTheEveryHoleParamsAndTheWorldModel) {
  params_["torque_nm"] = 80.0;
  params_["screw_type"] = "M16x50";
  params_["torque_per_hole_nm"] = {0.0, 30.0};
  params_["screw_type_per_hole"] = {"M8x20", ""};
  RunHarness h(type_, params_);
  look_up(h);
  EXPECT_EQ(h.operator_panel.newest()->spec.details["screw_type"], "M8x20");
  EXPECT_DOUBLE_EQ(h.operator_panel.newest()->spec.details["torque_nm"].get<double>(), 80.0);
  ASSERT_TRUE(h.operator_panel.answer("done"));
  EXPECT_EQ(h.operator_panel.newest()->spec.details["screw_type"], "M16x50");
  EXPECT_DOUBLE_EQ(h.operator_panel.newest()->spec.details["torque_nm"].get<double>(), 30.0);
  ASSERT_TRUE(h.operator_panel.answer("done"));
  EXPECT_TRUE(h.succeeded());
  // Without the every-hole params a hole left out per hole takes the world model's.
  params_.erase("torque_nm");
  params_.erase("screw_type");
  RunHarness w(type_, params_);
  look_up(w);
  EXPECT_DOUBLE_EQ(w.operator_panel.newest()->spec.details["torque_nm"].get<double>(), 60.0);
  ASSERT_TRUE(w.operator_panel.answer("done"));
  EXPECT_EQ(w.operator_panel.newest()->spec.details["screw_type"], "M10x30");
}

TEST_F(ScrewTest, PerHoleListsThatDoNotFitTheHolesFailAtTheirPath) {
  struct Case {
    const char* name;
    nlohmann::json value;
    const char* says;
  };
  for (const auto& c :
       {Case{"torque_per_hole_nm",
             {10.0},
             "/params/torque_per_hole_nm: expected 2 values, one per entry of /params/holes (or none), got 1"},
        Case{"screw_type_per_hole", {"a", "b", "c"}, "/params/screw_type_per_hole: expected 2 values"},
        Case{"screw_type_per_hole",
             {"M8", std::string(65, 'x')},
             "/params/screw_type_per_hole/1: expected at most 64 bytes, got 65"},
        Case{"torque_per_hole_nm", {10.0, -1.0}, "torque_per_hole_nm/1"},
        Case{"torque_per_hole_nm", 10.0, "torque_per_hole_nm"}}) {
    nlohmann::json params = params_;
    params[c.name] = c.value;
    RunHarness h(type_, params);
    h.run->start();
    ASSERT_TRUE(h.failed_with("BAD_PARAMS")) << params.dump();
    EXPECT_NE(h.result->message.find(c.says), std::string::npos) << h.result->message;
    EXPECT_TRUE(h.operator_panel.prompts.empty());
  }
}

TEST_F(ScrewTest, EachAnswerAndTheTimeoutEndTheRunWithItsCode) {
  struct Case {
    std::optional<std::string> answer;
    const char* code;
  };
  for (const auto& c :
       {Case{"failed", "SCREW_FAILED"}, Case{"abort", "OPERATOR_ABORTED"}, Case{std::nullopt, "OPERATOR_TIMEOUT"}}) {
    RunHarness h(type_, params_);
    look_up(h);
    ASSERT_TRUE(h.operator_panel.answer(c.answer));
    ASSERT_TRUE(h.failed_with(c.code)) << c.code << " got " << (h.result ? h.result->code : "nothing");
    EXPECT_NE(h.result->message.find("target/h1"), std::string::npos) << h.result->message;
    EXPECT_EQ(h.operator_panel.active(), 0u) << c.code << ": the prompt must be withdrawn";
  }
}

TEST_F(ScrewTest, AnUnknownHoleOrEntityFails) {
  {
    RunHarness h(type_, {{"holes", {"target/h9"}}});
    h.run->start();
    ASSERT_TRUE(h.world.answer_features(OpResult::success(), target_features()));
    ASSERT_TRUE(h.failed_with("UNKNOWN_FEATURE"));
    EXPECT_NE(h.result->message.find("h9"), std::string::npos);
  }
  {
    RunHarness h(type_, {{"holes", {"nothing/h1"}}});
    h.run->start();
    ASSERT_TRUE(h.world.answer_features(OpResult::failure("UNKNOWN_ENTITY", "no entity"), nlohmann::json::object()));
    EXPECT_TRUE(h.failed_with("UNKNOWN_ENTITY"));
  }
  {
    RunHarness h(type_, params_);
    h.run->start();
    ASSERT_TRUE(h.world.answer_features(OpResult::success(), target_features()));
    ASSERT_TRUE(h.resolver.answer(OpResult::failure("WORLD_UNREACHABLE", "no reply")));
    EXPECT_TRUE(h.failed_with("WORLD_UNREACHABLE"));
  }
}

TEST_F(ScrewTest, BadParamsFail) {
  for (const auto& params : {nlohmann::json{{"holes", nlohmann::json::array()}}, nlohmann::json::object(),
                             nlohmann::json{{"holes", {"target/h1"}}, {"torque_nm", -5}},
                             nlohmann::json{{"holes", {"target/h1"}}, {"timeout_per_hole_s", 0}}}) {
    RunHarness h(type_, params);
    h.run->start();
    ASSERT_TRUE(h.failed_with("BAD_PARAMS")) << params.dump();
    EXPECT_TRUE(h.operator_panel.prompts.empty());
  }
  // A hole ref without a feature part passes the string_list check but not the skill's.
  RunHarness h(type_, {{"holes", {"h1"}}});
  h.run->start();
  ASSERT_TRUE(h.failed_with("BAD_PARAMS"));
  EXPECT_NE(h.result->message.find("/params/holes"), std::string::npos);
}

TEST_F(ScrewTest, MissingDevicesAreDeviceUnavailable) {
  RunHarness h(type_, params_, [](Devices& d) { d.operator_panel = nullptr; });
  h.run->start();
  EXPECT_TRUE(h.failed_with("DEVICE_UNAVAILABLE"));
}

TEST_F(ScrewTest, ShutdownFromEveryStateIsStoppedWithThePromptWithdrawn) {
  {
    RunHarness h(type_, params_);
    h.run->start();
    h.run->shutdown("test");
    ASSERT_TRUE(h.stopped());
    EXPECT_FALSE(h.world.answer_features(OpResult::success(), target_features())) << "look-up not cancelled";
  }
  {
    RunHarness h(type_, params_);
    look_up(h);
    ASSERT_TRUE(h.operator_panel.answer("done"));
    h.run->shutdown("test");
    ASSERT_TRUE(h.stopped());
    EXPECT_EQ(h.operator_panel.active(), 0u);
    EXPECT_FALSE(h.operator_panel.answer("done")) << "a late answer must find no waiting prompt";
    EXPECT_EQ(h.results, 1);
  }
  RunHarness h(type_, params_);
  look_up(h);
  run_steps::expect_every_safe_stop_safe(h);
}

TEST(ScrewHoles, FindsTheHolesScrewData) {
  ScrewHole hole;
  hole.entity = "target";
  EXPECT_EQ(find_screw_hole(target_features(), "h2", hole), "");
  EXPECT_EQ(hole.screw_type, "M10x30");
  EXPECT_DOUBLE_EQ(hole.torque_nm, 45.0);
  EXPECT_NE(find_screw_hole(target_features(), "h3", hole), "");
  EXPECT_NE(find_screw_hole(nlohmann::json::object(), "h1", hole), "");
}

}  // namespace
}  // namespace rigger::skill_executor
