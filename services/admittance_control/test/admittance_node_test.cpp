// The admittance_control node in-process on a private domain: wrench stream in, setpoints out.
#include <gtest/gtest.h>

#include <chrono>
#include <memory>
#include <string>
#include <vector>

#include "admittance_node.hpp"
#include "rigger/dds/conversions.hpp"
#include "rigger/testing/domain.hpp"

namespace rigger::control {
namespace {

using namespace std::chrono_literals;

class AdmittanceNodeTest : public ::testing::Test {
 protected:
  explicit AdmittanceNodeTest(const std::string& config_json = "{}")
      : participant_(lease_.id()),
        loop_(participant_),
        announcer_(participant_, "admittance-test", "admittance_control"),
        context_{options_, null_logger(), participant_, loop_, announcer_, Config::parse(config_json, "test")},
        wrench_writer_(participant_, kWrenchTopic, dds::qos::sensor_stream()),
        robot_state_writer_(participant_, kRobotStateTopic, dds::qos::sensor_stream()),
        command_writer_(participant_, kCommandTopic, dds::qos::commands()),
        twists_(participant_, kCmdTwistTopic, dds::qos::setpoints()),
        crane_cmds_(participant_, kCraneCmdTopic, dds::qos::setpoints()),
        states_(participant_, kStateTopic, dds::qos::state()) {
    node_ = std::make_unique<AdmittanceNode>(context_);
    loop_.on_data(twists_, [this] {
      twists_.take([this](const rigger_sensing_TwistCommand& t, const dds_sample_info_t&) {
        twist_log_.push_back({t.seq, dds::to_domain(t.header.stamp), std::chrono::system_clock::now(),
                              dds::to_domain(t.twist), t.timeout_s});
      });
    });
    loop_.on_data(crane_cmds_, [this] {
      crane_cmds_.take([this](const rigger_crane_CraneVelocityCommand& c, const dds_sample_info_t&) {
        crane_log_.push_back({c.seq, Eigen::Vector3d(c.velocity_mps[0], c.velocity_mps[1], c.velocity_mps[2])});
      });
    });
    loop_.on_data(states_, [this] {
      states_.take([this](const rigger_admittance_AdmittanceState& s, const dds_sample_info_t&) {
        state_log_.push_back({s.fault, dds::to_string(s.fault_code), s.last_command_seq});
      });
    });
  }

  void publish_robot_state() {
    rigger_robot_RobotState s{};
    s.header.stamp = dds::wire_now();
    s.flange_pose = dds::to_wire(Eigen::Isometry3d::Identity());
    s.tool_pose = s.flange_pose;
    ASSERT_EQ(robot_state_writer_.write(s), DDS_RETCODE_OK);
  }

  void command(rigger_admittance_AdmittanceMode mode) {
    rigger_admittance_AdmittanceCommand c{};
    c.header.stamp = dds::wire_now();
    c.seq = ++command_seq_;
    c.mode = mode;
    c.reference = rigger_admittance_REFERENCE_NONE;
    c.source = dds::wire_string(source_);
    ASSERT_EQ(command_writer_.write(c), DDS_RETCODE_OK);
    const std::uint64_t seq = command_seq_;
    ASSERT_TRUE(loop_.run_until([&] { return !state_log_.empty() && state_log_.back().last_command_seq == seq; }, 5s));
  }

  /// A fresh wrench sample every 2 ms (the sensor stream) until stopped.
  void start_wrench_stream(const Vector6d& wrench_sensor) {
    wrench_ = wrench_sensor;
    wrench_timer_ = loop_.every(2ms, [this] {
      rigger_sensing_WrenchStamped w{};
      w.header.stamp = dds::wire_now();
      w.header.frame_id = dds::wire_string(sensor_frame_);
      w.wrench = dds::to_wire_wrench(wrench_);
      wrench_writer_.write(w);
    });
  }
  void stop_wrench_stream() { loop_.cancel(wrench_timer_); }

  struct TwistSample {
    std::uint64_t seq;
    WallTime stamp;
    WallTime received;
    Vector6d twist;
    double timeout_s;
  };
  struct CraneSample {
    std::uint64_t seq;
    Eigen::Vector3d velocity;
  };
  struct StateSample {
    bool fault;
    std::string code;
    std::uint64_t last_command_seq;
  };

  rigger::testing::DomainLease lease_;
  dds::ServiceOptions options_{"admittance-test", 0, "", "info"};
  dds::Participant participant_;
  dds::EventLoop loop_;
  dds::ServiceAnnouncer announcer_;
  dds::ServiceContext context_;
  dds::Writer<rigger_sensing_WrenchStamped> wrench_writer_;
  dds::Writer<rigger_robot_RobotState> robot_state_writer_;
  dds::Writer<rigger_admittance_AdmittanceCommand> command_writer_;
  dds::Reader<rigger_sensing_TwistCommand> twists_;
  dds::Reader<rigger_crane_CraneVelocityCommand> crane_cmds_;
  dds::Reader<rigger_admittance_AdmittanceState> states_;
  std::unique_ptr<AdmittanceNode> node_;
  std::vector<TwistSample> twist_log_;
  std::vector<CraneSample> crane_log_;
  std::vector<StateSample> state_log_;
  Vector6d wrench_ = Vector6d::Zero();
  dds::EventLoop::TimerId wrench_timer_ = 0;
  std::uint64_t command_seq_ = 0;
  std::string source_ = "test";
  std::string sensor_frame_ = "sensor";
};

class AdmittanceNodeCraneTest : public AdmittanceNodeTest {
 protected:
  AdmittanceNodeCraneTest() : AdmittanceNodeTest(R"({"crane": {"selected_axes": [true, true, true]}})") {}
};

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
  // The load pushes the robot up (+z, world): the crane must lift, i.e. hook height rate > 0 on the wire.
  start_wrench_stream((Vector6d() << 0, 0, 20, 0, 0, 0).finished());
  command(rigger_admittance_ADMITTANCE_ROBOT_AND_CRANE);
  ASSERT_TRUE(loop_.run_until([&] { return !crane_log_.empty() && crane_log_.back().velocity.z() > 0.001; }, 5s));
  for (std::size_t i = 1; i < crane_log_.size(); ++i) EXPECT_GT(crane_log_[i].seq, crane_log_[i - 1].seq);
  for (const CraneSample& c : crane_log_) EXPECT_GE(c.velocity.z(), 0.0) << "seq " << c.seq;
  // Back to OFF: one zero setpoint for each of robot and crane once their laws have stopped, then silence.
  command(rigger_admittance_ADMITTANCE_OFF);
  ASSERT_TRUE(loop_.run_until([&] { return crane_log_.back().velocity.isZero() && twist_log_.back().twist.isZero(); }, 5s));
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

}  // namespace
}  // namespace rigger::control
