// The admittance_control node in-process on a private domain: wrench stream in, setpoints out.
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <memory>
#include <string>
#include <vector>

#include "admittance_node_fixture.hpp"
#include "rigger/dds/conversions.hpp"
#include "rigger/dds/liveliness.hpp"
#include "rigger/protocol/admittance.hpp"
#include "rigger/protocol/crane.hpp"
#include "rigger/protocol/robot.hpp"
#include "rigger/protocol/vision.hpp"
#include "rigger/testing/domain.hpp"

namespace rigger::control {
namespace {

using namespace std::chrono_literals;
using namespace testing_support;

TEST_F(AdmittanceNodeCellTest, TheRobotBaseComesFromTheCellFile) {
  EXPECT_TRUE(node_->pose_world_base().translation().isApprox(Eigen::Vector3d(2.55, 2.0, 0.9), 1e-12));
}

TEST_F(AdmittanceNodeCellTest, VisualServoTwistIsTurnedIntoTheBaseAndMovedToTheTcp) {
  // The TCP at the base origin, i.e. (2.55, 2.0, 0.9) in the world; the load 0.2 m in front of it.
  publish_robot_state();
  start_wrench_stream(Vector6d::Zero());
  Eigen::Isometry3d load = Eigen::Isometry3d::Identity();
  load.translation() = Eigen::Vector3d(2.75, 2.0, 0.9);
  Eigen::Isometry3d target = Eigen::Isometry3d::Identity();
  target.translation() = Eigen::Vector3d(2.75, 2.0, 0.8);
  // Goal: the load turned 10 degrees about the world z over the target: the TCP, 0.2 m behind the
  // load's origin, must move sideways (w x r), not only turn.
  Eigen::Isometry3d goal = Eigen::Isometry3d::Identity();
  goal.translation() = Eigen::Vector3d(0.0, 0.0, 0.1);
  goal.linear() = Eigen::AngleAxisd(10.0 * kPi / 180.0, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  start_tracker(load, target);
  servo_command("load", "target", goal);
  ASSERT_TRUE(loop_.run_until([&] { return !twist_log_.empty() && twist_log_.back().twist(5) > 0.085; }, 5s));
  const Vector6d& twist = twist_log_.back().twist;
  // v_tcp = v_load + w x (p_tcp - p_load) = 0 + (0, 0, wz) x (-0.2, 0, 0) = (0, -0.2 wz, 0).
  EXPECT_NEAR(twist(1), -0.2 * twist(5), 0.02 * std::abs(twist(5)) + 1e-4);
  EXPECT_NEAR(twist(0), 0.0, 1e-6);
  EXPECT_NEAR(twist(2), 0.0, 1e-6);
}

TEST(AdmittanceNodeConfig, AMissingCellFileIsAConfigurationErrorNamingTheKey) {
  rigger::testing::DomainLease lease;
  service::ServiceOptions options{"admittance-test", 0, "", "info"};
  dds::Participant participant(lease.id());
  dds::EventLoop loop(participant);
  service::ServiceAnnouncer announcer(participant, "admittance-test", "admittance_control");
  service::ServiceContext context{options,     null_logger(),
                                  participant, loop,
                                  announcer,   Config::parse(R"({"cell_file": "/no/such/cell.json"})", "test.json")};
  try {
    AdmittanceNode node(context);
    FAIL() << "no error";
  } catch (const ConfigError& e) {
    EXPECT_EQ(e.pointer(), "/cell_file") << e.what();
    EXPECT_NE(std::string(e.what()).find("/no/such/cell.json"), std::string::npos) << e.what();
  }
}

TEST_F(AdmittanceNodeTest, ModeOffPublishesNoSetpoints) {
  publish_robot_state();
  start_wrench_stream((Vector6d() << 20, 0, 0, 0, 0, 0).finished());
  // The state is published at the crane rate: ten of them span about 100 robot periods.
  ASSERT_TRUE(loop_.run_until([&] { return state_log_.size() >= 10; }, 5s));
  EXPECT_TRUE(twist_log_.empty());
  EXPECT_TRUE(crane_log_.empty());
  EXPECT_FALSE(state_log_.back().fault);
}

TEST_F(AdmittanceNodeTest, ConstantForceGivesATwistInItsDirectionWithIncreasingSeqAndFreshStamps) {
  publish_robot_state();
  start_wrench_stream((Vector6d() << 20, 0, 0, 0, 0, 0).finished());
  command(rigger_admittance_ADMITTANCE_ROBOT);
  ASSERT_TRUE(loop_.run_until([&] { return !twist_log_.empty() && twist_log_.back().twist(0) > 0.05; }, 5s));
  ASSERT_GE(twist_log_.size(), 2u);
  for (std::size_t i = 1; i < twist_log_.size(); ++i) {
    EXPECT_GT(twist_log_[i].seq, twist_log_[i - 1].seq);
    EXPECT_GE(twist_log_[i].stamp, twist_log_[i - 1].stamp);
  }
  for (const TwistSample& s : twist_log_) {
    EXPECT_LT(to_seconds(s.received - s.stamp), 0.1) << "seq " << s.seq;
    EXPECT_GE(s.twist(0), 0.0) << "seq " << s.seq;
    EXPECT_NEAR(s.twist(1), 0.0, 1e-9);
    EXPECT_NEAR(s.twist(2), 0.0, 1e-9);
    EXPECT_GT(s.timeout_s, 0.0);
  }
  EXPECT_LE(twist_log_.back().twist(0), 0.25 + 1e-9);  // the configured velocity limit
  EXPECT_FALSE(state_log_.back().fault) << state_log_.back().code;
}

// A command's stiffness holds for that command only: the next command without gains is back on the configured
// free admittance (K = 0), so that one skill's spring never carries over into another skill's motion.
TEST_F(AdmittanceNodeTest, ACommandsStiffnessHoldsUntilTheNextCommand) {
  publish_robot_state();
  start_wrench_stream((Vector6d() << 20, 0, 0, 0, 0, 0).finished());
  // 20 N against 1000 N/m: the spring takes it at (20 - 3 N deadband) / 1000 = 17 mm, and the twist dies out.
  // Held: 50 twists in a row (0.1 s) below 2 mm/s, none during a fault (a stale wrench also gives zero; without
  // the spring the twist leaves 2 mm/s within 4 ms of any restart, at the 0.5 m/s² limit).
  command(rigger_admittance_ADMITTANCE_ROBOT, {1000, 1000, 1000, 0, 0, 0});
  std::size_t seen = 0;
  int quiet = 0;
  ASSERT_TRUE(loop_.run_until(
      [&] {
        for (; seen < twist_log_.size(); ++seen) {
          const bool still = std::abs(twist_log_[seen].twist(0)) < 0.002 && !state_log_.back().fault;
          quiet = still ? quiet + 1 : 0;
        }
        return quiet >= 50;
      },
      10s))
      << "the spring does not hold the tool against a constant force";
  // The configured gains again: a damper only, 17 N / 100 N s/m = 0.17 m/s.
  command(rigger_admittance_ADMITTANCE_ROBOT);
  ASSERT_TRUE(loop_.run_until([&] { return twist_log_.back().twist(0) > 0.15; }, 10s))
      << "the previous command's stiffness carried over";
  // Nonsense gains are refused as a whole: the command is not acknowledged and the law keeps going.
  std::vector<double> negative{-1, 0, 0, 0, 0, 0};
  write_command(rigger_admittance_ADMITTANCE_ROBOT, negative);
  const std::uint64_t refused = command_seq_;
  const std::size_t states = state_log_.size();
  ASSERT_TRUE(loop_.run_until([&] { return state_log_.size() >= states + 20; }, 5s));
  EXPECT_NE(state_log_.back().last_command_seq, refused);
  EXPECT_TRUE(loop_.run_until([&] { return twist_log_.back().twist(0) > 0.15; }, 5s)) << "the refusal changed the law";
}

TEST_F(AdmittanceNodeTest, StaleWrenchStreamGivesZeroOutputAndFaultWrenchStale) {
  publish_robot_state();
  start_wrench_stream((Vector6d() << 20, 0, 0, 0, 0, 0).finished());
  command(rigger_admittance_ADMITTANCE_ROBOT);
  ASSERT_TRUE(loop_.run_until([&] { return !twist_log_.empty() && twist_log_.back().twist(0) > 0.05; }, 5s));
  stop_wrench_stream();
  ASSERT_TRUE(loop_.run_until([&] { return !state_log_.empty() && state_log_.back().code == "WRENCH_STALE"; }, 5s));
  EXPECT_TRUE(state_log_.back().fault);
  const std::size_t n = twist_log_.size();
  ASSERT_TRUE(loop_.run_until([&] { return twist_log_.size() >= n + 5; }, 5s));
  for (std::size_t i = n; i < twist_log_.size(); ++i) {
    EXPECT_TRUE(twist_log_[i].twist.isZero(0.0)) << "seq " << twist_log_[i].seq;
  }
  // A fresh stream clears the fault by itself (a stale wrench does not latch).
  start_wrench_stream((Vector6d() << 20, 0, 0, 0, 0, 0).finished());
  ASSERT_TRUE(loop_.run_until([&] { return !state_log_.empty() && !state_log_.back().fault; }, 5s));
}

TEST_F(AdmittanceNodeTest, NoRobotStateMeansZeroOutputAndAFault) {
  start_wrench_stream((Vector6d() << 20, 0, 0, 0, 0, 0).finished());
  command(rigger_admittance_ADMITTANCE_ROBOT);
  ASSERT_TRUE(loop_.run_until([&] { return twist_log_.size() >= 5 && !state_log_.empty(); }, 5s));
  EXPECT_EQ(state_log_.back().code, kFaultNoRobotState);
  for (const TwistSample& s : twist_log_) EXPECT_TRUE(s.twist.isZero(0.0)) << "seq " << s.seq;
}

TEST_F(AdmittanceNodeCraneTest, UpwardPushRaisesTheHookOnTheWire) {
  publish_robot_state();
  start_crane_state();
  // The load pushes the robot up (+z, world): the crane must lift, i.e. hook height rate > 0 on the wire.
  start_wrench_stream((Vector6d() << 0, 0, 20, 0, 0, 0).finished());
  command(rigger_admittance_ADMITTANCE_ROBOT_AND_CRANE);
  ASSERT_TRUE(loop_.run_until([&] { return !crane_log_.empty() && crane_log_.back().velocity.z() > 0.001; }, 5s));
  for (std::size_t i = 1; i < crane_log_.size(); ++i) EXPECT_GT(crane_log_[i].seq, crane_log_[i - 1].seq);
  for (const CraneSample& c : crane_log_) EXPECT_GE(c.velocity.z(), 0.0) << "seq " << c.seq;
  // Back to OFF: one zero setpoint for each of robot and crane once their laws have stopped, then silence.
  command(rigger_admittance_ADMITTANCE_OFF);
  ASSERT_TRUE(
      loop_.run_until([&] { return crane_log_.back().velocity.isZero() && twist_log_.back().twist.isZero(); }, 5s));
  // Let both laws finish stopping (at most a few crane periods), then expect silence.
  const std::size_t settled = state_log_.size();
  ASSERT_TRUE(loop_.run_until([&] { return state_log_.size() >= settled + 5; }, 5s));
  EXPECT_TRUE(crane_log_.back().velocity.isZero());
  EXPECT_TRUE(twist_log_.back().twist.isZero());
  const std::size_t twists = twist_log_.size();
  const std::size_t cranes = crane_log_.size();
  const std::size_t states = state_log_.size();
  ASSERT_TRUE(loop_.run_until([&] { return state_log_.size() >= states + 5; }, 5s));
  EXPECT_EQ(twist_log_.size(), twists);
  EXPECT_EQ(crane_log_.size(), cranes);
}

TEST_F(AdmittanceNodeRopeTest, TrackedRopeOffsetMovesTheCraneOverTheLoadUntilTrackingStops) {
  // The hook 0.2 m behind the load's rope attachment in x (the attachment is 0.1 m above the load's
  // centre, which does not count: only the horizontal offset does). No force on the wrist.
  crane_position_ = Eigen::Vector3d(3.35, 1.75, 2.5);
  publish_robot_state();
  start_crane_state();
  start_wrench_stream(Vector6d::Zero());
  const auto tracker = start_tracker(Eigen::Isometry3d(Eigen::Translation3d(3.55, 1.75, 1.2)),
                                     Eigen::Isometry3d(Eigen::Translation3d(5.0, 2.0, 0.9)));
  command(rigger_admittance_ADMITTANCE_ROBOT_AND_CRANE);
  // k_delta * delta = 0.5/s * 0.2 m = 0.1 m/s towards the load, reached at the crane's acceleration limit.
  ASSERT_TRUE(loop_.run_until([&] { return !crane_log_.empty() && crane_log_.back().velocity.x() > 0.09; }, 5s));
  EXPECT_LT(crane_log_.back().velocity.x(), 0.1 + 1e-9);
  EXPECT_NEAR(crane_log_.back().velocity.y(), 0.0, 1e-9);
  // Tracking stops: the offset is no longer measured, and with no force the crane comes to rest
  // (below 0.1 mm/s: what remains is the law's own decaying state).
  loop_.cancel(tracker);
  ASSERT_TRUE(loop_.run_until([&] { return crane_log_.back().velocity.norm() < 1e-4; }, 5s))
      << crane_log_.back().velocity.transpose();
}

TEST(AdmittanceNodeConfig, RopeOffsetGainNeedsACellFileAndAnObjectWithARopeAttachment) {
  rigger::testing::DomainLease lease;
  service::ServiceOptions options{"admittance-test", lease.id(), "", "warn"};
  dds::Participant participant(lease.id());
  dds::EventLoop loop(participant);
  service::ServiceAnnouncer announcer(participant, "admittance-test", "admittance_control");
  const auto error_of = [&](const std::string& json) {
    service::ServiceContext context{options, null_logger(), participant,
                                    loop,    announcer,     Config::parse(json, "ac.json")};
    try {
      AdmittanceNode node(context);
    } catch (const ConfigError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  const std::string no_cell = error_of(R"({"crane": {"rope_offset_gain_per_s": 0.5}})");
  EXPECT_NE(no_cell.find("/crane/rope_offset_gain_per_s"), std::string::npos) << no_cell;
  EXPECT_NE(no_cell.find("needs cell_file"), std::string::npos) << no_cell;
  const std::string cell = std::string(RIGGER_SOURCE_DIR) + "/deploy/cell/simulated_cell.json";
  const std::string no_attachment =
      error_of(R"({"cell_file": ")" + cell + R"(", "rope_object": "target", "crane": {"rope_offset_gain_per_s": 0.5}})");
  EXPECT_NE(no_attachment.find("/rope_object"), std::string::npos) << no_attachment;
  EXPECT_NE(no_attachment.find("no rope_attachment"), std::string::npos) << no_attachment;
  const std::string unknown =
      error_of(R"({"cell_file": ")" + cell + R"(", "rope_object": "anvil", "crane": {"rope_offset_gain_per_s": 0.5}})");
  EXPECT_NE(unknown.find("anvil"), std::string::npos) << unknown;
  // Gain 0 (the default): no cell file needed, and the rope keys are still checked as known keys.
  EXPECT_EQ(error_of(R"({"rope_object": "load", "rope_offset_max_age_s": 0.5})"), "no error");
}

TEST_F(AdmittanceNodeTest, VisualServoMovesTheTcpTowardsTheGoalAndReportsTheError) {
  publish_robot_state();  // TCP at the base origin = world origin (no cell file)
  start_wrench_stream(Vector6d::Zero());
  Eigen::Isometry3d load = Eigen::Isometry3d::Identity();
  load.translation() = Eigen::Vector3d(0.0, 0.0, 0.5);
  Eigen::Isometry3d target = Eigen::Isometry3d::Identity();
  target.translation() = Eigen::Vector3d(0.3, 0.0, 0.4);
  Eigen::Isometry3d goal = Eigen::Isometry3d::Identity();
  goal.translation() = Eigen::Vector3d(0.0, 0.0, 0.1);  // on the target's top: 0.3 m along +x from the load
  start_tracker(load, target);
  servo_command("load", "target", goal);
  ASSERT_TRUE(loop_.run_until([&] { return !twist_log_.empty() && twist_log_.back().twist(0) > 0.05; }, 5s));
  const Vector6d& twist = twist_log_.back().twist;
  EXPECT_NEAR(twist(1), 0.0, 1e-6);
  EXPECT_NEAR(twist(2), 0.0, 1e-6);
  EXPECT_LE(twist(0), 0.1 + 1e-9);  // the servo's speed limit
  ASSERT_TRUE(loop_.run_until([&] { return std::isfinite(state_log_.back().servo_error_m); }, 5s));
  EXPECT_NEAR(state_log_.back().servo_error_m, 0.3, 1e-6);
  EXPECT_NEAR(state_log_.back().servo_error_rad, 0.0, 1e-6);
  EXPECT_FALSE(state_log_.back().servo_converged);
  EXPECT_FALSE(state_log_.back().fault) << state_log_.back().code;
}

TEST_F(AdmittanceNodeTest, VisualServoStopReasonIsReportedAndClearsWithGoodPoses) {
  publish_robot_state();
  start_wrench_stream(Vector6d::Zero());
  Eigen::Isometry3d target = Eigen::Isometry3d::Identity();
  target.translation() = Eigen::Vector3d(0.3, 0.0, 0.4);
  const auto poor = start_tracker(Eigen::Isometry3d::Identity(), target, 0.2);  // below min_quality 0.5
  servo_command("load", "target", Eigen::Isometry3d::Identity());
  ASSERT_TRUE(loop_.run_until([&] { return state_log_.back().code == "LOAD_QUALITY_LOW"; }, 5s))
      << state_log_.back().code;
  EXPECT_EQ(state_log_.back().mode, rigger_admittance_ADMITTANCE_ROBOT);  // not latched, the mode stays
  for (const TwistSample& t : twist_log_) EXPECT_TRUE(t.twist.isZero(1e-9)) << "seq " << t.seq;
  loop_.cancel(poor);
  start_tracker(Eigen::Isometry3d::Identity(), target);
  ASSERT_TRUE(loop_.run_until([&] { return !state_log_.back().fault; }, 5s)) << state_log_.back().code;
  ASSERT_TRUE(loop_.run_until([&] { return !twist_log_.empty() && twist_log_.back().twist(0) > 0.01; }, 5s));
}

TEST_F(AdmittanceNodeTest, VisualServoConvergedWhenTheLoadIsAtTheGoal) {
  publish_robot_state();
  start_wrench_stream(Vector6d::Zero());
  Eigen::Isometry3d target = Eigen::Isometry3d::Identity();
  target.translation() = Eigen::Vector3d(0.3, 0.0, 0.4);
  Eigen::Isometry3d goal = Eigen::Isometry3d::Identity();
  goal.translation() = Eigen::Vector3d(0.0, 0.0, 0.1);
  start_tracker(target * goal, target);
  servo_command("load", "target", goal);
  ASSERT_TRUE(loop_.run_until([&] { return state_log_.back().servo_converged; }, 5s));
  EXPECT_LT(state_log_.back().servo_error_m, 1e-9);
}

TEST_F(AdmittanceNodeTest, VisualServoRequestWithoutTargetIsRefusedAndNothingMoves) {
  publish_robot_state();
  start_wrench_stream(Vector6d::Zero());
  servo_command("load", "", Eigen::Isometry3d::Identity());
  EXPECT_EQ(state_log_.back().code, kFaultServoRequestInvalid);
  EXPECT_EQ(state_log_.back().mode, rigger_admittance_ADMITTANCE_OFF);
  const std::size_t states = state_log_.size();
  ASSERT_TRUE(loop_.run_until([&] { return state_log_.size() >= states + 5; }, 5s));
  EXPECT_TRUE(twist_log_.empty());
  EXPECT_EQ(state_log_.back().code, kFaultServoRequestInvalid);  // latched until the next command
  command(rigger_admittance_ADMITTANCE_OFF);
  EXPECT_FALSE(state_log_.back().fault);
}

TEST_F(AdmittanceNodeTest, VisualServoRequestWithNonUnitQuaternionIsRefused) {
  publish_robot_state();
  servo_command("load", "target", Eigen::Isometry3d::Identity(), 1.1);
  EXPECT_EQ(state_log_.back().code, kFaultServoRequestInvalid);
  EXPECT_EQ(state_log_.back().mode, rigger_admittance_ADMITTANCE_OFF);
  EXPECT_TRUE(twist_log_.empty());
}

TEST_F(AdmittanceNodeTest, LostCommanderStopsTheRobot) {
  publish_robot_state();
  start_wrench_stream((Vector6d() << 20, 0, 0, 0, 0, 0).finished());
  auto executor = std::make_unique<service::ServiceAnnouncer>(participant_, "executor-7", "skill_executor");
  executor->announce(service::ServiceStatus::kReady);
  source_ = "executor-7";
  command(rigger_admittance_ADMITTANCE_ROBOT);
  ASSERT_TRUE(loop_.run_until([&] { return !twist_log_.empty() && twist_log_.back().twist(0) > 0.05; }, 5s));
  EXPECT_FALSE(state_log_.back().fault) << state_log_.back().code;
  executor.reset();  // unregisters: the directory sees it leave at once
  ASSERT_TRUE(loop_.run_until([&] { return state_log_.back().code == kFaultCommanderLost; }, 5s));
  EXPECT_EQ(state_log_.back().mode, rigger_admittance_ADMITTANCE_OFF);
  ASSERT_TRUE(loop_.run_until([&] { return twist_log_.back().twist.isZero(0.0); }, 5s));
}

TEST_F(AdmittanceNodeTest, CommanderNeverSeenStopsTheRobotAfterTheGrace) {
  publish_robot_state();
  start_wrench_stream(Vector6d::Zero());
  source_ = "nobody";
  command(rigger_admittance_ADMITTANCE_ROBOT);
  ASSERT_TRUE(loop_.run_until([&] { return state_log_.back().code == kFaultCommanderLost; }, 5s));
  EXPECT_EQ(state_log_.back().mode, rigger_admittance_ADMITTANCE_OFF);
}

TEST_F(AdmittanceNodeCraneTest, CraneFaultStopsRobotAndCraneAndLatches) {
  publish_robot_state();
  start_crane_state();
  start_wrench_stream((Vector6d() << 20, 0, 0, 0, 0, 0).finished());
  command(rigger_admittance_ADMITTANCE_ROBOT_AND_CRANE);
  ASSERT_TRUE(loop_.run_until([&] { return !twist_log_.empty() && twist_log_.back().twist(0) > 0.05; }, 5s));
  EXPECT_FALSE(state_log_.back().fault) << state_log_.back().code;
  crane_fault_ = true;
  ASSERT_TRUE(loop_.run_until([&] { return state_log_.back().code == kFaultCraneFault; }, 5s));
  EXPECT_EQ(state_log_.back().mode, rigger_admittance_ADMITTANCE_OFF);
  ASSERT_TRUE(loop_.run_until(
      [&] { return twist_log_.back().twist.isZero(0.0) && !crane_log_.empty() && crane_log_.back().velocity.isZero(); },
      5s));
  crane_fault_ = false;  // the fault clears at the crane, but stays latched here until the next command
  const std::size_t states = state_log_.size();
  ASSERT_TRUE(loop_.run_until([&] { return state_log_.size() >= states + 5; }, 5s));
  EXPECT_EQ(state_log_.back().code, kFaultCraneFault);
  command(rigger_admittance_ADMITTANCE_ROBOT_AND_CRANE);
  EXPECT_FALSE(state_log_.back().fault) << state_log_.back().code;
}

TEST_F(AdmittanceNodeCraneTest, CraneLinkDownIsACraneFault) {
  publish_robot_state();
  start_crane_state();
  start_wrench_stream(Vector6d::Zero());
  command(rigger_admittance_ADMITTANCE_ROBOT_AND_CRANE);
  crane_link_ok_ = false;
  ASSERT_TRUE(loop_.run_until([&] { return state_log_.back().code == kFaultCraneFault; }, 5s));
}

TEST_F(AdmittanceNodeCraneTest, SilentCraneStateIsACraneFault) {
  publish_robot_state();
  start_wrench_stream(Vector6d::Zero());
  command(rigger_admittance_ADMITTANCE_ROBOT_AND_CRANE);
  ASSERT_TRUE(loop_.run_until([&] { return state_log_.back().code == kFaultCraneFault; }, 5s))
      << state_log_.back().code << ": " << state_log_.back().text;
}

}  // namespace
}  // namespace rigger::control
