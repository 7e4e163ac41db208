// Re-checking the world before a resume (relocalization.hpp): which done localizations the rest of the
// task relies on, the verdict against the world model's answer (moved / not moved / stale / world model
// unavailable / carried), and the plan that runs the moved object's localization again — restored into
// a real Engine to see what starts.
#include <gtest/gtest.h>

#include "relocalization.hpp"
#include "resume_plan.hpp"
#include "rigger/bt/engine.hpp"
#include "rigger/bt/tree_builder.hpp"
#include "unit_test_util.hpp"

namespace rigger::task_controller {
namespace {

using bt::NodeState;
using bt::build::build;
using bt::build::condition;
using bt::build::Node;
using bt::build::retry;
using bt::build::sequence;
using nlohmann::json;

skill::SkillLibrary library() {
  const json object = {{"name", "object"}, {"type", "string"}, {"min", 1}};
  return skill::SkillLibrary::from_json(
      {{"library_version", 1},
       {"skills",
        {{{"name", "Localize"}, {"kind", "skill"}, {"params", {object}}, {"postconditions", {"localized($object)"}}},
         {{"name", "ObjectLocalized"},
          {"kind", "condition"},
          {"params", {object, {{"name", "max_age_s"}, {"type", "number"}, {"default", 0}}}},
          {"postconditions", {"localized($object)"}}},
         {{"name", "Attach"},
          {"kind", "skill"},
          {"params", {object}},
          {"preconditions", {"localized($object)"}},
          {"postconditions", {"attached(robot,$object)"}}},
         {{"name", "Insert"},
          {"kind", "skill"},
          {"params", {object, {{"name", "target"}, {"type", "string"}}}},
          {"preconditions", {"localized($object)", "localized($target)"}}},
         {{"name", "Wait"}, {"kind", "skill"}, {"params", json::array()}}}}});
}

Node localize(const std::string& object) {
  return bt::build::skill("Localize", {}, {{"object", object}});
}
Node attach(const std::string& object) {
  return bt::build::skill("Attach", {}, {{"object", object}});
}
Node insert(const std::string& object, const std::string& target) {
  return bt::build::skill("Insert", {}, {{"object", object}, {"target", target}});
}

using testing::JournalingPort;

Eigen::Isometry3d at(double x, double y, double z, double yaw_deg = 0) {
  Eigen::Isometry3d p = Eigen::Isometry3d::Identity();
  p.linear() = Eigen::AngleAxisd(yaw_deg * M_PI / 180.0, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  p.translation() = Eigen::Vector3d(x, y, z);
  return p;
}

/// The killed controller's run of `root` (leaves succeed in `succeed` order; each localization's pose is
/// journaled as the controller does), then the plan and the re-check for the restarted one.
struct Resume {
  explicit Resume(const Node& root) : spec(build(root)), lib(library()), before(spec, first), after(spec, second) {
    before.start();
  }
  void succeed(const std::string& id, std::optional<Eigen::Isometry3d> pose = std::nullopt) {
    bt::LeafEvent e;
    e.kind = bt::LeafEventKind::kSuccess;
    e.activation = before.status(*before.find(id)).activation;
    before.on_leaf_event(id, e);
    if (pose) {
      const auto leaves = localizing_leaves(spec, lib);
      first.rows.push_back(
          {0, "t", id, kWorldRow, kLocalizedCode, localized_pose_row({leaves.at(id), *pose, 1'700'000'000.0})});
    }
  }
  std::vector<ObjectRecheck> checks() {
    plan = plan_resume(spec, first.rows);
    EXPECT_EQ(plan.error, "");
    return objects_to_recheck(spec, plan, first.rows, lib, settings);
  }
  /// Judges every check against `now` (same answer for each object), re-plans and starts the engine.
  std::vector<ObjectRecheck> resume(const world_client::Reply& now) {
    auto c = checks();
    for (auto& check : c) judge(check, now, settings, spec);
    plan = plan_resume(spec, first.rows, leaves_to_relocalize(c));
    EXPECT_EQ(plan.error, "");
    EXPECT_TRUE(after.start(plan.restoration).acted_on());
    return c;
  }

  bt::TreeSpec spec;
  skill::SkillLibrary lib;
  RecheckSettings settings;
  JournalingPort first, second;
  bt::Engine before, after;
  ResumePlan plan;
};

world_client::Reply seen(const Eigen::Isometry3d& pose, double age_s = 2.0) {
  world_client::Reply n;
  n.ok = true;
  n.code = "OK";
  n.localized = true;
  n.pose = pose;
  n.age_s = age_s;
  return n;
}

TEST(Relocalization, TheJournaledPoseRoundTripsAndOtherRowsAreNotPoses) {
  const LocalizedPose p{"load", at(1.5, -0.25, 0.75, 30), 1'700'000'123.5};
  const auto back = localized_pose_from_row({0, "t", "root/0", kWorldRow, kLocalizedCode, localized_pose_row(p)});
  ASSERT_TRUE(back.has_value());
  EXPECT_EQ(back->object, "load");
  EXPECT_TRUE(back->pose_world_object.isApprox(p.pose_world_object, 1e-12));
  EXPECT_DOUBLE_EQ(back->stamp_s, p.stamp_s);
  EXPECT_FALSE(localized_pose_from_row({0, "t", "root/0", "NODE", kLocalizedCode, localized_pose_row(p)}));
  EXPECT_FALSE(localized_pose_from_row({0, "t", "root/0", kWorldRow, kLocalizedCode, "{not json"}));
  EXPECT_FALSE(localized_pose_from_row({0, "t", "root/0", kWorldRow, kLocalizedCode, R"({"object": "load"})"}));
}

TEST(Relocalization, OnlyLocalizationsThatTheRestOfTheTaskUsesAreChecked) {
  // load and bolt localized; the interrupted Wait and the pending Insert use load and target only.
  Resume r(sequence({localize("load"), localize("bolt"), bt::build::skill("Wait"), insert("load", "target")}));
  r.succeed("root/0", at(1, 0, 0));
  r.succeed("root/1", at(2, 0, 0));
  const auto c = r.checks();
  ASSERT_EQ(c.size(), 1U);
  EXPECT_EQ(c[0].object, "load");
  EXPECT_EQ(c[0].localized_by, std::vector<std::string>{"root/0"});
  EXPECT_EQ(c[0].used_by, std::vector<std::string>{"root/3"});
  ASSERT_TRUE(c[0].recorded.has_value());
  EXPECT_TRUE(c[0].recorded->pose_world_object.isApprox(at(1, 0, 0)));
  EXPECT_DOUBLE_EQ(c[0].max_age_s, 300.0);
}

TEST(Relocalization, NotMovedStaysDoneAndNothingRunsAgain) {
  Resume r(sequence({localize("load"), bt::build::skill("Wait"), insert("load", "target")}));
  r.succeed("root/0", at(1, 0, 0));
  const auto c = r.resume(seen(at(1.004, 0.003, 0, 1.0)));  // 5 mm, 1 deg: within 10 mm / 2 deg
  ASSERT_EQ(c.size(), 1U);
  EXPECT_EQ(c[0].verdict, "unchanged");
  EXPECT_FALSE(c[0].relocalize);
  EXPECT_TRUE(c[0].preconditions_hold);
  EXPECT_NEAR(c[0].displacement_m, 0.005, 1e-9);
  EXPECT_NEAR(c[0].rotation_deg, 1.0, 1e-9);
  EXPECT_EQ(r.plan.done, std::vector<std::string>{"root/0"});
  EXPECT_TRUE(r.plan.relocalize.empty());
  EXPECT_EQ(r.second.starts, std::vector<std::string>{"root/1"});  // the interrupted Wait (the operator's rerun)
  EXPECT_NE(c[0].reason.find("stays done"), std::string::npos) << c[0].reason;
}

// The tracker is idle unless a skill asks it: a pose observed before the controller stopped says nothing
// of where the object is now, however close it is to the journaled one.
TEST(Relocalization, APoseNobodyObservedSinceTheControllerStoppedIsNoEvidenceAndItRunsAgain) {
  Resume r(sequence({localize("load"), bt::build::skill("Wait"), insert("load", "target")}));
  r.succeed("root/0", at(1, 0, 0));
  for (auto& row : r.first.rows) row.stamp_s = 1000.0;  // the crashed controller's rows
  r.first.rows.push_back({1005.0, "t", "", "TASK", "INTERRUPTED", "the controller stopped"});
  auto c = r.checks();
  ASSERT_EQ(c.size(), 1U);
  EXPECT_DOUBLE_EQ(c[0].interrupted_at_s, 1000.0);

  ObjectRecheck unseen = c[0];
  unseen.checked_at_s = 1010.0;
  judge(unseen, seen(at(1, 0, 0), 12.0), r.settings, r.spec);  // observed at 998 s
  EXPECT_EQ(unseen.verdict, "unconfirmed");
  EXPECT_TRUE(unseen.relocalize);
  EXPECT_FALSE(unseen.preconditions_hold);
  EXPECT_NE(unseen.reason.find("nothing has seen load since the controller stopped"), std::string::npos) << unseen.reason;
  EXPECT_NE(unseen.reason.find("will run again"), std::string::npos) << unseen.reason;

  ObjectRecheck looked = c[0];
  looked.checked_at_s = 1010.0;
  judge(looked, seen(at(1.002, 0, 0), 4.0), r.settings, r.spec);  // observed at 1006 s, 2 mm off
  EXPECT_EQ(looked.verdict, "unchanged");
  EXPECT_FALSE(looked.relocalize);

  ObjectRecheck unknown_time = c[0];  // the caller did not say when it asked: the rule is not applied
  judge(unknown_time, seen(at(1, 0, 0), 12.0), r.settings, r.spec);
  EXPECT_EQ(unknown_time.verdict, "unchanged");
}

TEST(Relocalization, MovedRunsTheLocalizationAgainFirstAndSaysWhyInPlainWords) {
  Resume r(sequence({localize("load"), bt::build::skill("Wait"), insert("load", "target")}));
  r.succeed("root/0", at(1, 0, 0));
  const auto c = r.resume(seen(at(1.045, 0, 0)));
  ASSERT_EQ(c.size(), 1U);
  EXPECT_EQ(c[0].verdict, "moved");
  EXPECT_TRUE(c[0].relocalize);
  EXPECT_FALSE(c[0].preconditions_hold);
  // "load moved 45 mm and 0.0 deg since it was localized at 22:13:20 UTC; Localize(load) (root/0) will run again"
  EXPECT_NE(c[0].reason.find("load moved 45 mm"), std::string::npos) << c[0].reason;
  EXPECT_NE(c[0].reason.find("since it was localized at 22:13:20 UTC"), std::string::npos) << c[0].reason;
  EXPECT_NE(c[0].reason.find("Localize(load) (root/0) will run again"), std::string::npos) << c[0].reason;
  EXPECT_TRUE(r.plan.done.empty());
  EXPECT_EQ(r.plan.relocalize, std::vector<std::string>{"root/0"});
  EXPECT_EQ(r.plan.ask, std::vector<std::string>{"root/1"});
  EXPECT_EQ(r.second.starts, std::vector<std::string>{"root/0"});  // the localization runs first
  EXPECT_NE(describe_plan(r.plan, r.spec).find("re-localized"), std::string::npos);
  // A turn alone counts too.
  Resume turned(sequence({localize("load"), bt::build::skill("Wait"), insert("load", "target")}));
  turned.succeed("root/0", at(1, 0, 0));
  EXPECT_EQ(turned.resume(seen(at(1, 0, 0, 5.0)))[0].verdict, "moved");
}

TEST(Relocalization, AStalePoseRunsTheLocalizationAgainTheRecipesMaxAgeFirst) {
  Resume r(sequence({localize("load"), bt::build::skill("Wait"), insert("load", "target")}));
  r.succeed("root/0", at(1, 0, 0));
  const auto c = r.resume(seen(at(1, 0, 0), 301.0));
  EXPECT_EQ(c[0].verdict, "stale");
  EXPECT_TRUE(c[0].relocalize);
  EXPECT_NE(c[0].reason.find("older than its max age 300.0 s"), std::string::npos) << c[0].reason;
  EXPECT_EQ(r.second.starts, std::vector<std::string>{"root/0"});

  // The recipe's ObjectLocalized(load, 5 s) sets the object's max age.
  Resume g(sequence({localize("load"), bt::build::skill("Wait"),
                     condition("ObjectLocalized", {{"object", "load"}, {"max_age_s", 5.0}}), insert("load", "t")}));
  g.succeed("root/0", at(1, 0, 0));
  const auto gc = g.resume(seen(at(1, 0, 0), 6.0));
  EXPECT_DOUBLE_EQ(gc[0].max_age_s, 5.0);
  EXPECT_EQ(gc[0].verdict, "stale");
}

TEST(Relocalization, AWorldModelThatDoesNotAnswerErrsOnTheSafeSide) {
  Resume r(sequence({localize("load"), bt::build::skill("Wait"), insert("load", "target")}));
  r.succeed("root/0", at(1, 0, 0));
  world_client::Reply none;
  none.code = "WORLD_UNREACHABLE";
  none.message = "no world model answered within 1000 ms";
  const auto c = r.resume(none);
  EXPECT_EQ(c[0].verdict, "unknown");
  EXPECT_TRUE(c[0].relocalize);
  EXPECT_FALSE(c[0].preconditions_hold);
  EXPECT_NE(c[0].reason.find("the world model did not answer about load (WORLD_UNREACHABLE"), std::string::npos)
      << c[0].reason;
  EXPECT_EQ(r.plan.relocalize, std::vector<std::string>{"root/0"});
  const json j = to_json(c);
  EXPECT_EQ(j[0]["world_model"], "WORLD_UNREACHABLE: no world model answered within 1000 ms");
  EXPECT_TRUE(j[0]["pose_age_s"].is_null());
  EXPECT_TRUE(j[0]["displacement_mm"].is_null());
}

TEST(Relocalization, NoJournaledPoseOrNotLocalizedRunsItAgain) {
  Resume r(sequence({localize("load"), bt::build::skill("Wait"), insert("load", "target")}));
  r.succeed("root/0");  // killed before the world model's answer was journaled
  auto c = r.resume(seen(at(1, 0, 0)));
  EXPECT_EQ(c[0].verdict, "unrecorded");
  EXPECT_TRUE(c[0].relocalize);

  Resume lost(sequence({localize("load"), bt::build::skill("Wait"), insert("load", "target")}));
  lost.succeed("root/0", at(1, 0, 0));
  world_client::Reply n = seen(at(1, 0, 0));
  n.localized = false;
  EXPECT_EQ(lost.resume(n)[0].verdict, "not_localized");
}

TEST(Relocalization, AnObjectTheTaskAttachedMovesWithTheRobotAndItsLocalizationStaysDone) {
  Resume r(sequence({localize("target"), localize("load"), attach("load"), insert("load", "target")}));
  r.succeed("root/0", at(3, 0, 0));
  r.succeed("root/1", at(1, 0, 0));
  r.succeed("root/2");  // Insert runs (and moves the load) when the controller dies
  auto c = r.checks();
  ASSERT_EQ(c.size(), 2U);
  for (auto& check : c)
    judge(check, seen(check.object == "load" ? at(1.4, 0.1, 0.2) : at(3.002, 0, 0)), r.settings, r.spec);
  const auto& load = c[0].object == "load" ? c[0] : c[1];
  const auto& target = c[0].object == "load" ? c[1] : c[0];
  EXPECT_EQ(load.verdict, "carried");
  EXPECT_EQ(load.carried_by, "root/2");
  EXPECT_FALSE(load.relocalize);
  EXPECT_NE(load.reason.find("moves with the robot"), std::string::npos) << load.reason;
  EXPECT_EQ(target.verdict, "unchanged");
  EXPECT_TRUE(leaves_to_relocalize(c).empty());
}

TEST(Relocalization, ALocalizationInsideADoneSubtreeRunsAloneItsDoneSiblingsStayDone) {
  // The paper's shape: Retry(Sequence[Localize(load), Attach(load)]) done, a later step running.
  Resume r(sequence({retry(2, sequence({localize("load"), bt::build::skill("Wait")})), bt::build::skill("Wait"),
                     insert("load", "t")}));
  r.succeed("root/0/0/0", at(1, 0, 0));
  r.succeed("root/0/0/1");
  const auto c = r.resume(seen(at(1.1, 0, 0)));
  ASSERT_EQ(c.size(), 1U);
  EXPECT_EQ(c[0].verdict, "moved");
  EXPECT_EQ(r.plan.relocalize, std::vector<std::string>{"root/0/0/0"});
  EXPECT_EQ(r.plan.done, std::vector<std::string>{"root/0/0/1"});
  EXPECT_EQ(r.second.starts, std::vector<std::string>{"root/0/0/0"});
  // It succeeds: the done Wait reports at once, then the interrupted one starts (the operator's rerun).
  bt::LeafEvent e;
  e.kind = bt::LeafEventKind::kSuccess;
  e.activation = r.after.status(*r.after.find("root/0/0/0")).activation;
  EXPECT_TRUE(r.after.on_leaf_event("root/0/0/0", e).acted_on());
  EXPECT_EQ(r.after.status(*r.after.find("root/0")).state, NodeState::kSuccess);
  EXPECT_EQ(r.second.starts, (std::vector<std::string>{"root/0/0/0", "root/1"}));
}

}  // namespace
}  // namespace rigger::task_controller
