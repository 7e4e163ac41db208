#pragma once
// The admittance_control node in-process on a private domain (a test fixture): wrench, robot state,
// tracker and crane streams in; setpoints and the node's state out.

#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <memory>
#include <string>
#include <vector>

#include "admittance_node.hpp"
#include "rigger/dds/conversions.hpp"
#include "rigger/dds/liveliness.hpp"
#include "rigger/protocol/admittance.hpp"
#include "rigger/protocol/crane.hpp"
#include "rigger/protocol/robot.hpp"
#include "rigger/protocol/vision.hpp"
#include "rigger/testing/domain.hpp"

namespace rigger::control::testing_support {

using namespace std::chrono_literals;

class AdmittanceNodeTest : public ::testing::Test {
 protected:
  explicit AdmittanceNodeTest(const std::string& config_json = "{}")
      : participant_(lease_.id()),
        loop_(participant_),
        announcer_(participant_, "admittance-test", "admittance_control"),
        liveliness_(participant_, dds::liveliness_lease() / 3, 0ms),  // as run_service asserts it
        context_{options_, null_logger(), participant_, loop_, announcer_, Config::parse(config_json, "test")},
        wrench_writer_(participant_, protocol::robot::kWrench),
        robot_state_writer_(participant_, protocol::robot::kState),
        command_writer_(participant_, protocol::admittance::kCommand),
        twists_(participant_, protocol::robot::kCmdTwist),
        crane_cmds_(participant_, protocol::crane::kCmdVelocity),
        states_(participant_, protocol::admittance::kState),
        tracker_writer_(participant_, protocol::vision::kTrackerPose),
        crane_state_writer_(participant_, protocol::crane::kState) {
    announcer_.announce(service::ServiceStatus::kReady);  // the commands' source ("admittance-test") is alive
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
        state_log_.push_back({s.fault, dds::to_string(s.fault_code), dds::to_string(s.fault_text), s.last_command_seq,
                              s.mode, s.servo_converged, s.servo_error_m, s.servo_error_rad});
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

  void command(rigger_admittance_AdmittanceMode mode, std::vector<double> stiffness = {}) {
    write_command(mode, stiffness);
    const std::uint64_t seq = command_seq_;
    ASSERT_TRUE(loop_.run_until([&] { return !state_log_.empty() && state_log_.back().last_command_seq == seq; }, 5s));
  }
  /// Writes a command (reference NONE, the robot law's stiffness when given) without waiting for it.
  void write_command(rigger_admittance_AdmittanceMode mode, std::vector<double>& stiffness) {
    rigger_admittance_AdmittanceCommand c{};
    c.header.stamp = dds::wire_now();
    c.seq = ++command_seq_;
    c.mode = mode;
    c.reference = rigger_admittance_REFERENCE_NONE;
    c.source = dds::wire_string(source_);
    dds::wire_sequence(c.stiffness, stiffness);
    ASSERT_EQ(command_writer_.write(c), DDS_RETCODE_OK);
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
    std::string text;
    std::uint64_t last_command_seq;
    rigger_admittance_AdmittanceMode mode;
    bool servo_converged;
    double servo_error_m;
    double servo_error_rad;
  };

  /// A visual-servo command; waits for the state that acknowledges it.
  void servo_command(const std::string& object, const std::string& target, const Eigen::Isometry3d& goal,
                     double quaternion_scale = 1.0) {
    rigger_admittance_AdmittanceCommand c{};
    c.header.stamp = dds::wire_now();
    c.seq = ++command_seq_;
    c.mode = rigger_admittance_ADMITTANCE_ROBOT;
    c.reference = rigger_admittance_REFERENCE_VISUAL_SERVO;
    c.servo_object = dds::wire_string(object);
    c.servo_target = dds::wire_string(target);
    c.servo_goal_in_target = dds::to_wire(goal);
    c.servo_goal_in_target.orientation.w *= quaternion_scale;
    c.servo_goal_in_target.orientation.x *= quaternion_scale;
    c.servo_goal_in_target.orientation.y *= quaternion_scale;
    c.servo_goal_in_target.orientation.z *= quaternion_scale;
    c.source = dds::wire_string(source_);
    ASSERT_EQ(command_writer_.write(c), DDS_RETCODE_OK);
    const std::uint64_t seq = command_seq_;
    ASSERT_TRUE(loop_.run_until([&] { return !state_log_.empty() && state_log_.back().last_command_seq == seq; }, 5s));
  }

  /// Tracker poses of the load and the target at 30 Hz (world frame, fresh stamps) until cancelled.
  dds::EventLoop::TimerId start_tracker(const Eigen::Isometry3d& load, const Eigen::Isometry3d& target,
                                        double load_quality = 0.9) {
    return loop_.every(33ms, [this, load, target, load_quality] {
      for (const auto& [id, pose] : {std::pair<const char*, Eigen::Isometry3d>{"load", load}, {"target", target}}) {
        rigger_vision_TrackedPose p{};
        p.header.stamp = dds::wire_now();
        p.header.frame_id = const_cast<char*>("world");
        p.object_id = const_cast<char*>(id);
        p.pose.pose = dds::to_wire(pose);
        p.quality = std::string(id) == "load" ? load_quality : 0.9;
        p.tracked = true;
        tracker_writer_.write(p);
      }
    });
  }

  /// A crane state every 20 ms (as the gateway publishes it) with `fault` and `link_ok` as set.
  void start_crane_state() {
    crane_timer_ = loop_.every(20ms, [this] {
      rigger_crane_CraneState c{};
      c.header.stamp = dds::wire_now();
      c.link_ok = crane_link_ok_;
      c.fault = crane_fault_;
      for (int i = 0; i < 3; ++i) c.position_m[i] = crane_position_[i];
      c.fault_text = const_cast<char*>(crane_fault_ ? "estop" : "");
      crane_state_writer_.write(c);
    });
  }

  rigger::testing::DomainLease lease_;
  service::ServiceOptions options_{"admittance-test", 0, "", "info"};
  dds::Participant participant_;
  dds::EventLoop loop_;
  service::ServiceAnnouncer announcer_;
  dds::LivelinessAsserter liveliness_;
  service::ServiceContext context_;
  dds::Writer<rigger_sensing_WrenchStamped> wrench_writer_;
  dds::Writer<rigger_robot_RobotState> robot_state_writer_;
  dds::Writer<rigger_admittance_AdmittanceCommand> command_writer_;
  dds::Reader<rigger_sensing_TwistCommand> twists_;
  dds::Reader<rigger_crane_CraneVelocityCommand> crane_cmds_;
  dds::Reader<rigger_admittance_AdmittanceState> states_;
  dds::Writer<rigger_vision_TrackedPose> tracker_writer_;
  dds::Writer<rigger_crane_CraneState> crane_state_writer_;
  dds::EventLoop::TimerId crane_timer_ = 0;
  bool crane_fault_ = false;
  bool crane_link_ok_ = true;
  Eigen::Vector3d crane_position_ = Eigen::Vector3d::Zero();
  std::unique_ptr<AdmittanceNode> node_;
  std::vector<TwistSample> twist_log_;
  std::vector<CraneSample> crane_log_;
  std::vector<StateSample> state_log_;
  Vector6d wrench_ = Vector6d::Zero();
  dds::EventLoop::TimerId wrench_timer_ = 0;
  std::uint64_t command_seq_ = 0;
  std::string source_ = "admittance-test";
  std::string sensor_frame_ = "sensor";
};

class AdmittanceNodeCraneTest : public AdmittanceNodeTest {
 protected:
  AdmittanceNodeCraneTest() : AdmittanceNodeTest(R"({"crane": {"selected_axes": [true, true, true]}})") {}
};

/// The measured rope offset on: the load's rope attachment from the simulated cell's file.
class AdmittanceNodeRopeTest : public AdmittanceNodeTest {
 protected:
  AdmittanceNodeRopeTest()
      : AdmittanceNodeTest(R"({"cell_file": ")" + std::string(RIGGER_SOURCE_DIR) +
                           R"(/deploy/cell/simulated_cell.json", "crane": {"rope_offset_gain_per_s": 0.5}})") {}
};

class AdmittanceNodeCellTest : public AdmittanceNodeTest {
 protected:
  AdmittanceNodeCellTest()
      : AdmittanceNodeTest(R"({"cell_file": ")" + std::string(RIGGER_SOURCE_DIR) +
                           R"(/deploy/cell/simulated_cell.json", "robot_id": "robot"})") {}
};

}  // namespace rigger::control::testing_support
