// SkillRun: parameter checking against the description and feature_ref resolution before the FSM starts.
#include <gtest/gtest.h>

#include "rigger/skill_sdk/testing/run_harness.hpp"
#include "rigger/skill_sdk/params.hpp"
#include "rigger/skill_sdk/skill_registry.hpp"

namespace rigger::skill_sdk {
namespace {

using testing::RunHarness;

// One state that succeeds at once with the resolved grasp's x coordinate in its message.
class GraspSkill final : public Skill {
 public:
  GraspSkill() {
    add_state({"report", [this] {
                 const auto& f = ctx().features().at("grasp");
                 succeed(f.ref + "@" + f.frame + " x=" + std::to_string(f.pose.translation().x()));
               },
               nothing_to_stop});
  }
  static SkillType type() {
    skill::SkillDescription d;
    d.name = "Grasp";
    d.params = {params::feature("grasp"), params::number("speed_mps").unit("m/s").range(0.0, 1.0).fallback(0.1)};
    d.resources = {"robot"};
    return {d, [] { return std::make_unique<GraspSkill>(); }};
  }
};

class SkillRunTest : public ::testing::Test {
 protected:
  SkillType type_ = GraspSkill::type();
};

TEST_F(SkillRunTest, BadParamsFailBeforeAnythingStartsAndNameEachParameter) {
  RunHarness h(type_, {{"speed_mps", 7.0}, {"colour", "red"}});
  h.run->start();
  ASSERT_TRUE(h.result);
  EXPECT_EQ(h.result->code, "BAD_PARAMS");
  EXPECT_NE(h.result->message.find("/params/speed_mps"), std::string::npos) << h.result->message;
  EXPECT_NE(h.result->message.find("/params/colour"), std::string::npos) << h.result->message;
  EXPECT_NE(h.result->message.find("/params/grasp"), std::string::npos) << h.result->message;  // required, missing
  EXPECT_EQ(h.run->skill(), nullptr);
  EXPECT_EQ(h.resolver.pending(), 0u);
}

TEST_F(SkillRunTest, FeatureRefsAreResolvedBeforeTheFsmStarts) {
  RunHarness h(type_, {{"grasp", "load/grasp_top"}});
  h.run->start();
  EXPECT_EQ(h.run->skill(), nullptr);
  ASSERT_NE(h.resolver.oldest(), nullptr);
  EXPECT_EQ(h.resolver.oldest()->ref, "load/grasp_top");
  EXPECT_EQ(h.resolver.oldest()->frame, "world");
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  pose.translation().x() = 1.25;
  ASSERT_TRUE(h.resolver.answer(OpResult::success(), pose));
  ASSERT_TRUE(h.result);
  EXPECT_EQ(h.result->kind, SkillResult::Kind::kSuccess);
  EXPECT_EQ(h.result->message, "load/grasp_top@world x=1.250000");
  EXPECT_DOUBLE_EQ(h.run->params().at("speed_mps").get<double>(), 0.1);  // default filled
}

TEST_F(SkillRunTest, AnUnresolvableFeatureFailsWithTheWorldModelsCode) {
  RunHarness h(type_, {{"grasp", "load/grasp_nowhere"}});
  h.run->start();
  ASSERT_TRUE(h.resolver.answer(OpResult::failure("UNKNOWN_FEATURE", "load has no feature grasp_nowhere")));
  ASSERT_TRUE(h.result);
  EXPECT_EQ(h.result->code, "UNKNOWN_FEATURE");
  EXPECT_NE(h.result->message.find("/params/grasp"), std::string::npos);
  EXPECT_EQ(h.run->skill(), nullptr);
}

TEST_F(SkillRunTest, ShutdownWhileResolvingStopsAtOnceAndCancelsTheQuery) {
  RunHarness h(type_, {{"grasp", "load/grasp_top"}});
  h.run->start();
  ASSERT_EQ(h.resolver.pending(), 1u);
  h.run->shutdown("test");
  ASSERT_TRUE(h.result);
  EXPECT_EQ(h.result->kind, SkillResult::Kind::kStopped);
  EXPECT_EQ(h.resolver.pending(), 0u);
  EXPECT_EQ(h.run->skill(), nullptr);
}

TEST_F(SkillRunTest, FeatureRefWithoutAWorldModelIsDeviceUnavailable) {
  int results = 0;
  std::optional<SkillResult> result;
  testing::FakeTimers timers;
  SkillRun run(type_, {{"grasp", "load/grasp_top"}}, Devices{}, timers, null_logger(),
               {nullptr, [&](const SkillResult& r) {
                  ++results;
                  result = r;
                }});
  run.start();
  ASSERT_TRUE(result);
  EXPECT_EQ(result->code, "DEVICE_UNAVAILABLE");
  EXPECT_EQ(results, 1);
}

TEST(SkillRegistryTest, LibraryJsonNamesSkillsAndRefusesUnknownOnes) {
  SkillRegistry registry;
  registry.add(GraspSkill::type());
  const auto library = registry.library_json({"Grasp"});
  EXPECT_EQ(library.at("library_version"), 1);
  ASSERT_EQ(library.at("skills").size(), 1u);
  EXPECT_EQ(library["skills"][0].at("name"), "Grasp");
  EXPECT_EQ(library["skills"][0].at("resources"), nlohmann::json::array({"robot"}));
  try {
    registry.library_json({"Fly"});
    FAIL() << "an unknown skill was described";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("unknown skill 'Fly'; this binary has: Grasp"), std::string::npos) << e.what();
  }
}

TEST(SkillRegistryTest, RefusesDuplicatesAndInvalidDescriptions) {
  SkillRegistry registry;
  registry.add(GraspSkill::type());
  EXPECT_THROW(registry.add(GraspSkill::type()), std::invalid_argument);
  SkillType bad = GraspSkill::type();
  bad.description.name = "lowercase";  // names must start with a capital letter
  EXPECT_THROW(registry.add(bad), std::invalid_argument);
}

}  // namespace
}  // namespace rigger::skill_sdk
