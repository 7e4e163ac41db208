// The cell devices on DDS, in one process on a domain of its own, with the test playing the other side:
// Localize end to end over the tracker topics and the world model's update/update_result (the test is
// tracker and world model), Screw's prompt/response path (the test is the operator UI), the crane
// monitor and the admittance controller's confirmation by state.
#include <gtest/gtest.h>

#include "dds_cell_devices.hpp"
#include "executor_node.hpp"
#include "rigger/dds/conversions.hpp"
#include "rigger/dds/qos.hpp"
#include "rigger/operator_protocol/prompt.hpp"
#include "rigger/protocol/admittance.hpp"
#include "rigger/protocol/crane.hpp"
#include "rigger/protocol/operator.hpp"
#include "rigger/protocol/vision.hpp"
#include "rigger/protocol/world.hpp"
#include "rigger/testing/domain.hpp"
#include "sdk_testing.hpp"
#include "skills/localize.hpp"
#include "skills/screw.hpp"

namespace rigger::skill_executor {
namespace {

using namespace std::chrono_literals;

class DdsCellDevicesTest : public ::testing::Test {
 protected:
  ::rigger::testing::DomainLease domain_;
  dds::Participant participant_{domain_.id()};
  dds::EventLoop loop_{participant_};
  LoopTimers timers_{loop_};

  template <typename R>
  static bool wait_matched(const R& reader) {
    return reader.wait_for_writers(1, 5s);
  }
  /// Runs the loop until `run` ended (or 10 s).
  bool run_to_end(const std::optional<SkillResult>& result) {
    return loop_.run_until([&] { return result.has_value(); }, 10s);
  }
};

TEST_F(DdsCellDevicesTest, LocalizeTracksOnceAndWaitsForTheWorldModelsAcceptance) {
  DdsVisionTracker tracker(participant_, loop_, null_logger(), "perception-skills");
  world_client::WorldClient client(participant_, loop_, null_logger(), "perception-skills-1");
  DdsWorldAccess world(client, participant_, loop_, null_logger(), "perception-skills-1");

  // The test as vision tracker: answers each TRACK_ONCE with one pose, the first of low quality.
  dds::Reader<rigger_vision_TrackerCommand> commands(participant_, protocol::vision::kTrackerCommand);
  dds::Writer<rigger_vision_TrackedPose> poses(participant_, protocol::vision::kTrackerPose);
  std::vector<std::tuple<std::string, std::string, rigger_vision_TrackerCommandKind>> received;
  std::optional<WallTime> good_stamp;
  loop_.on_data(commands, [&] {
    commands.take([&](const rigger_vision_TrackerCommand& c, const dds_sample_info_t&) {
      received.emplace_back(dds::to_string(c.object_id), dds::to_string(c.source), c.kind);
      rigger_vision_TrackedPose p{};
      const std::string frame = "world", object = "load";
      const WallTime stamp = std::chrono::system_clock::now() + 1ms;
      p.header.stamp = dds::to_wire(stamp);
      p.header.frame_id = dds::wire_string(frame);
      p.object_id = dds::wire_string(object);
      p.tracked = true;
      p.quality = received.size() == 1 ? 0.3 : 0.9;
      if (p.quality > 0.5 && !good_stamp) good_stamp = stamp;
      Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
      pose.translation() = Eigen::Vector3d(1.5, -0.5, 0.8);
      p.pose.pose = dds::to_wire(pose);
      poses.write(p);
    });
  });
  // The test as world model: accepts every update.
  dds::Reader<rigger_world_EntityUpdate> updates(participant_, protocol::world::kUpdate);
  dds::Writer<rigger_world_UpdateResult> results(participant_, protocol::world::kUpdateResult);
  std::vector<rigger_world_EntityUpdate> applied;
  std::vector<std::string> update_entities, update_parents;
  loop_.on_data(updates, [&] {
    updates.take([&](const rigger_world_EntityUpdate& u, const dds_sample_info_t&) {
      applied.push_back(u);
      update_entities.push_back(dds::to_string(u.entity_id));
      update_parents.push_back(dds::to_string(u.parent_frame));
      rigger_world_UpdateResult r{};
      const std::string code = "ACCEPTED";
      r.source = u.source;
      r.seq = u.seq;
      r.entity_id = u.entity_id;
      r.accepted = true;
      r.code = dds::wire_string(code);
      r.reason = dds::wire_string("");
      results.write(r);
    });
  });
  ASSERT_TRUE(poses.wait_for_readers(1, 5s));
  ASSERT_TRUE(results.wait_for_readers(1, 5s));
  ASSERT_TRUE(wait_matched(updates));
  ASSERT_TRUE(wait_matched(commands));

  Devices devices;
  devices.tracker = &tracker;
  devices.world_access = &world;
  const SkillType type{LocalizeSkill::describe(), [] { return std::make_unique<LocalizeSkill>(); }};
  std::optional<SkillResult> result;
  SkillRun run(type, {{"object", "load"}, {"timeout_s", 5.0}}, devices, timers_, null_logger(),
               {nullptr, [&](const SkillResult& r) { result = r; }});
  run.start();
  ASSERT_TRUE(run_to_end(result));
  EXPECT_EQ(result->kind, SkillResult::Kind::kSuccess) << result->code << " " << result->message;
  ASSERT_GE(received.size(), 2u) << "the low-quality pose must have been followed by another TRACK_ONCE";
  for (const auto& [object, source, kind] : received) {
    EXPECT_EQ(object, "load");
    EXPECT_EQ(source, "perception-skills");
    EXPECT_EQ(kind, rigger_vision_TRACK_ONCE);
  }
  ASSERT_EQ(applied.size(), 1u);
  EXPECT_EQ(update_entities[0], "load");
  EXPECT_EQ(update_parents[0], "world");
  EXPECT_TRUE(applied[0].has_pose);
  EXPECT_TRUE(applied[0].has_localized);
  EXPECT_TRUE(applied[0].localized);
  EXPECT_TRUE(applied[0].has_quality);
  EXPECT_DOUBLE_EQ(applied[0].quality, 0.9);
  EXPECT_NEAR(applied[0].pose.pose.position.x, 1.5, 1e-12);
  ASSERT_TRUE(good_stamp);
  EXPECT_EQ(dds::to_domain(applied[0].stamp), *good_stamp) << "the update carries the image's stamp";
}

TEST_F(DdsCellDevicesTest, ScrewPromptsOverDdsAndWithdrawsEachPromptAfterItsAnswer) {
  DdsOperatorPanel panel(participant_, loop_, null_logger(), "operator-skills");
  testing::FakeWorldAccess world;
  testing::FakeResolver resolver;
  // The test as operator UI: answers "maybe" (not an option: ignored), then "done".
  dds::Reader<rigger_operator_ui_OperatorPrompt> prompts(participant_, protocol::operator_ui::kPrompt);
  dds::Writer<rigger_operator_ui_OperatorResponse> responses(participant_, protocol::operator_ui::kResponse);
  struct Seen {
    std::string prompt_id, kind;
    bool active;
    nlohmann::json details;
    std::vector<std::string> options;
  };
  std::vector<Seen> seen;
  const auto respond = [&](const std::string& prompt_id, const std::string& answer) {
    operator_protocol::write_response(responses, prompt_id, answer, "test-operator", "");
  };
  loop_.on_data(prompts, [&] {
    prompts.take([&](const rigger_operator_ui_OperatorPrompt& p, const dds_sample_info_t& info) {
      if (!info.valid_data) return;
      seen.push_back({dds::to_string(p.prompt_id), dds::to_string(p.kind), p.active,
                      nlohmann::json::parse(dds::to_string(p.details_json)), dds::to_string_vector(p.options)});
      if (p.active) {
        respond(seen.back().prompt_id, "maybe");
        respond(seen.back().prompt_id, "done");
      }
    });
  });
  ASSERT_TRUE(responses.wait_for_readers(1, 5s));
  ASSERT_TRUE(wait_matched(prompts));

  Devices devices;
  devices.operator_panel = &panel;
  devices.world_access = &world;
  devices.world = &resolver;
  const SkillType type{ScrewSkill::describe(), [] { return std::make_unique<ScrewSkill>(); }};
  std::optional<SkillResult> result;
  SkillRun run(type, {{"holes", {"target/h1", "target/h2"}}, {"timeout_per_hole_s", 5.0}}, devices, timers_,
               null_logger(), {nullptr, [&](const SkillResult& r) { result = r; }});
  run.start();
  ASSERT_TRUE(
      world.answer_features(OpResult::success(), {{"screw_holes",
                                                   {{{"id", "h1"}, {"screw_type", "M12x40"}, {"torque_nm", 60.0}},
                                                    {{"id", "h2"}, {"screw_type", "M12x40"}, {"torque_nm", 60.0}}}}}));
  Eigen::Isometry3d hole = Eigen::Isometry3d::Identity();
  hole.translation() = Eigen::Vector3d(2.0, 1.0, 0.4);
  ASSERT_TRUE(resolver.answer(OpResult::success(), hole));
  ASSERT_TRUE(resolver.answer(OpResult::success(), hole));
  ASSERT_TRUE(run_to_end(result));
  EXPECT_EQ(result->kind, SkillResult::Kind::kSuccess) << result->code << " " << result->message;
  // Each prompt: published active, then withdrawn; distinct ids.
  ASSERT_TRUE(loop_.run_until([&] { return seen.size() >= 4; }, 5s));
  ASSERT_EQ(seen.size(), 4u);
  EXPECT_TRUE(seen[0].active);
  EXPECT_EQ(seen[0].kind, "screw");
  EXPECT_EQ(seen[0].options, (std::vector<std::string>{"done", "failed", "abort"}));
  EXPECT_EQ(seen[0].details["hole"], "h1");
  EXPECT_EQ(seen[0].details["screw_type"], "M12x40");
  EXPECT_DOUBLE_EQ(seen[0].details["torque_nm"].get<double>(), 60.0);
  EXPECT_DOUBLE_EQ(seen[0].details["position_m"][0].get<double>(), 2.0);
  EXPECT_FALSE(seen[1].active);
  EXPECT_EQ(seen[1].prompt_id, seen[0].prompt_id);
  EXPECT_TRUE(seen[2].active);
  EXPECT_EQ(seen[2].details["hole"], "h2");
  EXPECT_NE(seen[2].prompt_id, seen[0].prompt_id);
  EXPECT_FALSE(seen[3].active);
}

TEST_F(DdsCellDevicesTest, AnUnansweredPromptTimesOutAndIsWithdrawnOnDestruction) {
  dds::Reader<rigger_operator_ui_OperatorPrompt> prompts(participant_, protocol::operator_ui::kPrompt);
  std::vector<bool> active;
  loop_.on_data(prompts, [&] {
    prompts.take([&](const rigger_operator_ui_OperatorPrompt& p, const dds_sample_info_t& info) {
      if (info.valid_data) active.push_back(p.active);
    });
  });
  std::optional<std::optional<std::string>> answer;
  {
    DdsOperatorPanel panel(participant_, loop_, null_logger(), "operator-skills");
    OperatorPromptSpec spec;
    spec.kind = "confirm";
    spec.options = {"done"};
    panel.ask(spec, 50ms, [&](std::optional<std::string> a) { answer = a; });
    ASSERT_TRUE(loop_.run_until([&] { return answer.has_value(); }, 5s));
    EXPECT_FALSE(answer->has_value());
  }
  ASSERT_TRUE(loop_.run_until([&] { return active.size() >= 2; }, 5s));
  EXPECT_EQ(active, (std::vector<bool>{true, false}));
}

rigger_crane_CraneState crane_state(bool healthy, WallTime stamp = std::chrono::system_clock::now()) {
  rigger_crane_CraneState s{};
  s.header.stamp = dds::to_wire(stamp);
  s.link_ok = true;
  s.ready = healthy;
  s.estop = !healthy;
  s.fault_text = dds::wire_string("");
  return s;
}

TEST_F(DdsCellDevicesTest, CraneMonitorChecksFreshStatesWatchesAndRequestsExternalControl) {
  DdsCraneMonitor crane(participant_, loop_, null_logger(), "robot-skills");
  dds::Writer<rigger_crane_CraneState> state(participant_, protocol::crane::kState);
  dds::Reader<rigger_crane_CraneControl> control(participant_, protocol::crane::kControl);
  std::vector<rigger_crane_CraneControlKind> controls;
  loop_.on_data(control, [&] {
    control.take([&](const rigger_crane_CraneControl& c, const dds_sample_info_t&) { controls.push_back(c.kind); });
  });
  ASSERT_TRUE(state.wait_for_readers(1, 5s));
  ASSERT_TRUE(wait_matched(control));

  // An old healthy state does not answer a check; an e-stop does, with CRANE_FAULT.
  std::optional<OpResult> check;
  crane.check_health(1s, 5s, [&](const OpResult& r) { check = r; });
  state.write(crane_state(true, std::chrono::system_clock::now() - 10s));
  loop_.run_until([] { return false; }, 100ms);
  EXPECT_FALSE(check);
  state.write(crane_state(false));
  ASSERT_TRUE(loop_.run_until([&] { return check.has_value(); }, 5s));
  EXPECT_EQ(check->code, kCraneFault);
  EXPECT_NE(check->message.find("e-stop"), std::string::npos) << check->message;

  // A fresh healthy state already received answers a new check at once.
  state.write(crane_state(true));
  loop_.run_until([] { return false; }, 100ms);
  check.reset();
  crane.check_health(1s, 5s, [&](const OpResult& r) { check = r; });
  ASSERT_TRUE(loop_.run_until([&] { return check.has_value(); }, 5s));
  EXPECT_TRUE(check->ok) << check->message;

  // No state for max_silence: the watch fires.
  std::optional<OpResult> problem;
  crane.watch_health(100ms, [&](const OpResult& r) { problem = r; });
  ASSERT_TRUE(loop_.run_until([&] { return problem.has_value(); }, 5s));
  EXPECT_EQ(problem->code, kCraneFault);
  EXPECT_NE(problem->message.find("no rigger/crane/state"), std::string::npos);

  // External control: requested, confirmed once enabled and granted.
  std::optional<OpResult> external;
  crane.request_external(5s, [&](const OpResult& r) { external = r; });
  ASSERT_TRUE(loop_.run_until([&] { return !controls.empty(); }, 5s));
  EXPECT_EQ(controls[0], rigger_crane_CRANE_REQUEST_EXTERNAL);
  auto granted = crane_state(true);
  granted.enabled = true;
  granted.external_control = true;
  state.write(granted);
  ASSERT_TRUE(loop_.run_until([&] { return external.has_value(); }, 5s));
  EXPECT_TRUE(external->ok) << external->message;
}

TEST_F(DdsCellDevicesTest, CraneHealthCheckWaitsForThePlcLinkUpToItsTimeout) {
  DdsCraneMonitor crane(participant_, loop_, null_logger(), "robot-skills");
  dds::Writer<rigger_crane_CraneState> state(participant_, protocol::crane::kState);
  ASSERT_TRUE(state.wait_for_readers(1, 5s));
  auto no_link = crane_state(true);
  no_link.link_ok = false;

  // The link stays down: the check fails at its timeout, not at the first state, and says why.
  std::optional<OpResult> check;
  const auto t0 = std::chrono::steady_clock::now();
  crane.check_health(1s, 300ms, [&](const OpResult& r) { check = r; });
  state.write(no_link);
  ASSERT_TRUE(loop_.run_until([&] { return check.has_value(); }, 5s));
  EXPECT_GE(std::chrono::steady_clock::now() - t0, 300ms);
  EXPECT_EQ(check->code, kCraneFault);
  EXPECT_NE(check->message.find("no link to the PLC"), std::string::npos) << check->message;

  // The gateway (re)connects while a check waits: the check passes.
  check.reset();
  crane.check_health(1s, 5s, [&](const OpResult& r) { check = r; });
  state.write(crane_state(true));
  ASSERT_TRUE(loop_.run_until([&] { return check.has_value(); }, 5s));
  EXPECT_TRUE(check->ok) << check->message;
}

TEST_F(DdsCellDevicesTest, AdmittanceCommandsAreConfirmedByTheStatesSeqAndOffWaitsForRest) {
  DdsAdmittanceController admittance(participant_, loop_, null_logger(), "robot-skills");
  dds::Reader<rigger_admittance_AdmittanceCommand> commands(participant_, protocol::admittance::kCommand);
  dds::Writer<rigger_admittance_AdmittanceState> state(participant_, protocol::admittance::kState);
  struct Received {
    std::uint64_t seq;
    rigger_admittance_AdmittanceMode mode;
    rigger_admittance_ReferenceSource reference;
    std::string object, target, source;
    double goal_z;
  };
  std::vector<Received> received;
  loop_.on_data(commands, [&] {
    commands.take([&](const rigger_admittance_AdmittanceCommand& c, const dds_sample_info_t&) {
      received.push_back({c.seq, c.mode, c.reference, dds::to_string(c.servo_object), dds::to_string(c.servo_target),
                          dds::to_string(c.source), c.servo_goal_in_target.position.z});
    });
  });
  ASSERT_TRUE(state.wait_for_readers(1, 5s));
  ASSERT_TRUE(wait_matched(commands));
  const auto publish = [&](std::uint64_t seq, rigger_admittance_AdmittanceMode mode,
                           rigger_admittance_ReferenceSource reference, double twist) {
    rigger_admittance_AdmittanceState s{};
    s.header.stamp = dds::wire_now();
    s.mode = mode;
    s.reference = reference;
    s.fault_code = dds::wire_string("");
    s.fault_text = dds::wire_string("");
    s.robot_twist.linear.x = twist;
    s.last_command_seq = seq;
    state.write(s);
  };

  AdmittanceRequest servo;
  servo.mode = AdmittanceModeRequest::kRobotAndCrane;
  servo.reference = AdmittanceReference::kVisualServo;
  servo.servo_object = "load";
  servo.servo_target = "target";
  servo.servo_goal_in_target.translation().z() = 0.12;
  std::optional<OpResult> engaged;
  admittance.command(servo, 5s, [&](const OpResult& r) { engaged = r; });
  ASSERT_TRUE(loop_.run_until([&] { return !received.empty(); }, 5s));
  EXPECT_EQ(received[0].mode, rigger_admittance_ADMITTANCE_ROBOT_AND_CRANE);
  EXPECT_EQ(received[0].reference, rigger_admittance_REFERENCE_VISUAL_SERVO);
  EXPECT_EQ(received[0].object, "load");
  EXPECT_EQ(received[0].target, "target");
  EXPECT_EQ(received[0].source, "robot-skills");
  EXPECT_DOUBLE_EQ(received[0].goal_z, 0.12);
  publish(received[0].seq - 1, rigger_admittance_ADMITTANCE_ROBOT_AND_CRANE, rigger_admittance_REFERENCE_VISUAL_SERVO,
          0);
  loop_.run_until([] { return false; }, 100ms);
  EXPECT_FALSE(engaged) << "a state of an older command confirmed ours";
  publish(received[0].seq, rigger_admittance_ADMITTANCE_ROBOT_AND_CRANE, rigger_admittance_REFERENCE_VISUAL_SERVO,
          0.05);
  ASSERT_TRUE(loop_.run_until([&] { return engaged.has_value(); }, 5s));
  EXPECT_TRUE(engaged->ok) << engaged->message;

  std::optional<OpResult> off;
  admittance.command(AdmittanceRequest{}, 5s, [&](const OpResult& r) { off = r; });
  ASSERT_TRUE(loop_.run_until([&] { return received.size() == 2; }, 5s));
  EXPECT_EQ(received[1].mode, rigger_admittance_ADMITTANCE_OFF);
  publish(received[1].seq, rigger_admittance_ADMITTANCE_OFF, rigger_admittance_REFERENCE_NONE, 0.05);  // ramping
  loop_.run_until([] { return false; }, 100ms);
  EXPECT_FALSE(off) << "OFF confirmed while the robot still moved";
  publish(received[1].seq, rigger_admittance_ADMITTANCE_OFF, rigger_admittance_REFERENCE_NONE, 0.0);
  ASSERT_TRUE(loop_.run_until([&] { return off.has_value(); }, 5s));
  EXPECT_TRUE(off->ok) << off->message;

  // A command acknowledged with another mode was refused.
  std::optional<OpResult> refused;
  admittance.command(servo, 5s, [&](const OpResult& r) { refused = r; });
  ASSERT_TRUE(loop_.run_until([&] { return received.size() == 3; }, 5s));
  publish(received[2].seq, rigger_admittance_ADMITTANCE_OFF, rigger_admittance_REFERENCE_NONE, 0.0);
  ASSERT_TRUE(loop_.run_until([&] { return refused.has_value(); }, 5s));
  EXPECT_EQ(refused->code, "ADMITTANCE_REFUSED");
}

TEST(CraneProblem, NamesEveryProblem) {
  CraneSnapshot s;
  s.link_ok = true;
  s.ready = true;
  EXPECT_FALSE(crane_problem(s));
  s.fault = true;
  s.fault_code = 7;
  s.fault_text = "drive";
  s.overload = true;
  ASSERT_TRUE(crane_problem(s));
  EXPECT_NE(crane_problem(s)->find("fault 7 (drive)"), std::string::npos);
  EXPECT_NE(crane_problem(s)->find("overload"), std::string::npos);
  s = CraneSnapshot{};
  s.ready = true;
  EXPECT_NE(crane_problem(s)->find("no link"), std::string::npos);
}

}  // namespace
}  // namespace rigger::skill_executor
