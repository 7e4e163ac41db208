// Closed-loop acceptance of admittance_control in the simulated cell, every process real: cell_sim
// (MuJoCo: crane, 40 kg load on the rope, iiwa with magnet, F/T sensor, camera; its PLC emulator on
// Modbus TCP), crane_gateway, vision_tracker (camera images -> rigger/tracker/pose) and
// admittance_control, each with its shipped configuration from deploy/config. The test attaches the
// robot to the load itself (raw DDS: cmd_motion to pre_grasp and grasp_side, gripper energize), then:
//   - push: a constant horizontal force on the load (SIM_SET_LOAD_FORCE) in ROBOT_AND_CRANE without a
//     reference moves the robot's TCP and the crane in the push direction;
//   - servo: ROBOT_AND_CRANE + VISUAL_SERVO from ~0.5 m away brings the load's TRUE pose
//     (rigger/sim/ground_truth) within 5 mm and 1 degree of target * insertion, hoist included;
//   - commander lost: the servo's commander leaves rigger/system/service_state mid-insertion (it
//     unregisters, or a real process announcing its id is SIGKILLed) and everything stops.
// Real time (cell_sim's configured real_time_factor 1): the PLC's watchdog and the gateway run on it.
// Figures are printed; the assertions are the acceptance criteria, never durations of the machine.
#include <signal.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <iostream>
#include <map>

#include <gtest/gtest.h>

#include "cell_sim_test_support.hpp"
#include "control_config.hpp"
#include "rigger/cell_config/cell_cad.hpp"
#include "rigger/dds/liveliness.hpp"
#include "rigger/protocol/admittance.hpp"
#include "rigger/protocol/crane.hpp"
#include "rigger/protocol/robot.hpp"
#include "rigger/protocol/sim.hpp"
#include "rigger/protocol/vision.hpp"
#include "rigger/service/service_state.hpp"
#include "rigger/testing/require.hpp"

namespace rigger::testing {
namespace {

using namespace std::chrono_literals;

constexpr double kRadToDeg = 180.0 / 3.14159265358979323846;
/// The interaction force the insertion recipe allows (recipes/crane_insert.json, ForceMonitor max_force_n).
constexpr double kForceLimitN = 150.0;
constexpr const char* kCommanderId = "closed-loop-test";

struct RobotView {
  Eigen::Isometry3d tool_pose_base = Eigen::Isometry3d::Identity();
  Eigen::Vector3d tool_velocity_base_mps = Eigen::Vector3d::Zero();
};

struct CraneView {
  bool link_ok = false;
  bool fault = false;
  bool external_control = false;
  std::string fault_text;
  Eigen::Vector3d position_m = Eigen::Vector3d::Zero();
  Eigen::Vector3d velocity_mps = Eigen::Vector3d::Zero();
};

struct AdmittanceView {
  rigger_admittance_AdmittanceMode mode = rigger_admittance_ADMITTANCE_OFF;
  bool fault = false;
  std::string fault_code;
  std::string fault_text;
  bool servo_converged = false;
  double servo_error_m = 0.0;
  double servo_error_rad = 0.0;
  std::uint64_t last_command_seq = 0;
};

/// The pose error of `pose` with respect to `goal`: distance (m) and rotation angle (rad).
std::pair<double, double> pose_error(const Eigen::Isometry3d& pose, const Eigen::Isometry3d& goal) {
  const double distance = (goal.translation() - pose.translation()).norm();
  const double angle = Eigen::AngleAxisd(goal.linear() * pose.linear().transpose()).angle();
  return {distance, std::abs(angle)};
}

struct PushResult;

class ClosedLoopTest : public MultiProcessTest {
 protected:
  void SetUp() override {
    sim_ = std::make_unique<SimChannel>(cell_);
    auto& p = cell_.participant();
    truth_reader_ = std::make_unique<dds::Reader<rigger_vision_TrackedPose>>(p, protocol::sim::kGroundTruth);
    tracker_reader_ = std::make_unique<dds::Reader<rigger_vision_TrackedPose>>(p, protocol::vision::kTrackerPose);
    robot_reader_ = std::make_unique<dds::Reader<rigger_robot_RobotState>>(p, protocol::robot::kState);
    wrench_reader_ = std::make_unique<dds::Reader<rigger_sensing_WrenchStamped>>(p, protocol::robot::kWrench);
    motion_status_reader_ = std::make_unique<dds::Reader<rigger_robot_MotionStatus>>(p, protocol::robot::kMotionStatus);
    gripper_reader_ = std::make_unique<dds::Reader<rigger_robot_GripperState>>(p, protocol::robot::kGripperState);
    crane_reader_ = std::make_unique<dds::Reader<rigger_crane_CraneState>>(p, protocol::crane::kState);
    admittance_reader_ =
        std::make_unique<dds::Reader<rigger_admittance_AdmittanceState>>(p, protocol::admittance::kState);
    motion_writer_ = std::make_unique<dds::Writer<rigger_robot_MotionCommand>>(p, protocol::robot::kCmdMotion);
    gripper_writer_ = std::make_unique<dds::Writer<rigger_robot_GripperCommand>>(p, protocol::robot::kGripperCmd);
    crane_control_writer_ = std::make_unique<dds::Writer<rigger_crane_CraneControl>>(p, protocol::crane::kControl);
    tracker_command_writer_ =
        std::make_unique<dds::Writer<rigger_vision_TrackerCommand>>(p, protocol::vision::kTrackerCommand);
    admittance_writer_ =
        std::make_unique<dds::Writer<rigger_admittance_AdmittanceCommand>>(p, protocol::admittance::kCommand);
    // The test is the skill here: it announces itself, and its commands name it as their source.
    commander_ = std::make_unique<service::ServiceAnnouncer>(p, kCommanderId, "integration_test");
    commander_->announce(service::ServiceStatus::kReady);
    // As run_service does: the announcement's liveliness is asserted (MANUAL_BY_PARTICIPANT).
    liveliness_ = std::make_unique<dds::LivelinessAsserter>(p, dds::liveliness_lease() / 3, 0ms);

    auto& loop = cell_.loop();
    loop.on_data(*truth_reader_, [this] {
      truth_reader_->take([this](const rigger_vision_TrackedPose& s, const dds_sample_info_t&) {
        truth_[dds::to_string(s.object_id)] = dds::to_domain(s.pose.pose);
        on_truth();
      });
    });
    loop.on_data(*tracker_reader_, [this] {
      tracker_reader_->take([this](const rigger_vision_TrackedPose& s, const dds_sample_info_t&) {
        if (s.tracked) tracked_[dds::to_string(s.object_id)] = dds::to_domain(s.pose.pose);
      });
    });
    loop.on_data(*robot_reader_, [this] {
      robot_reader_->take([this](const rigger_robot_RobotState& s, const dds_sample_info_t&) {
        robot_ = RobotView{dds::to_domain(s.tool_pose), dds::to_domain(s.tool_twist).head<3>()};
      });
    });
    loop.on_data(*wrench_reader_, [this] {
      wrench_reader_->take([this](const rigger_sensing_WrenchStamped& s, const dds_sample_info_t&) {
        max_force_n_ = std::max(max_force_n_, dds::to_domain(s.wrench).head<3>().norm());
      });
    });
    loop.on_data(*motion_status_reader_, [this] {
      motion_status_reader_->take([this](const rigger_robot_MotionStatus& s, const dds_sample_info_t&) {
        motions_[dds::to_string(s.motion_id)] = {s.state, dds::to_string(s.code) + " " + dds::to_string(s.message)};
      });
    });
    loop.on_data(*gripper_reader_, [this] {
      gripper_reader_->take(
          [this](const rigger_robot_GripperState& s, const dds_sample_info_t&) { gripper_holding_ = s.holding; });
    });
    loop.on_data(*crane_reader_, [this] {
      crane_reader_->take([this](const rigger_crane_CraneState& s, const dds_sample_info_t&) {
        CraneView v;
        v.link_ok = s.link_ok;
        v.fault = s.fault;
        v.external_control = s.external_control;
        v.fault_text = dds::to_string(s.fault_text);
        v.position_m = Eigen::Vector3d(s.position_m[0], s.position_m[1], s.position_m[2]);
        v.velocity_mps = Eigen::Vector3d(s.velocity_mps[0], s.velocity_mps[1], s.velocity_mps[2]);
        crane_ = v;
      });
    });
    loop.on_data(*admittance_reader_, [this] {
      admittance_reader_->take([this](const rigger_admittance_AdmittanceState& s, const dds_sample_info_t&) {
        AdmittanceView v;
        v.mode = s.mode;
        v.fault = s.fault;
        v.fault_code = dds::to_string(s.fault_code);
        v.fault_text = dds::to_string(s.fault_text);
        v.servo_converged = s.servo_converged;
        v.servo_error_m = s.servo_error_m;
        v.servo_error_rad = s.servo_error_rad;
        v.last_command_seq = s.last_command_seq;
        admittance_ = v;
      });
    });

    const std::string cell_file = repo_file("deploy/cell/simulated_cell.json");
    pose_world_base_ = control::entity_pose_from_cell_file(cell_file, "robot");
    // The load's features as every process gets them: derived from the STEP models (rigger_cell_cad).
    cell_file_ = cell::load_cell_file_with_cad(cell_file);
  }

  void TearDown() override {
    // Leave the cell at rest before the processes are stopped.
    if (admittance_writer_ && cell_.has("admittance_control")) command(rigger_admittance_ADMITTANCE_OFF);
    MultiProcessTest::TearDown();
  }

  /// The load's feature `id` (an approach waypoint or a grasp frame), in the load's frame.
  Eigen::Isometry3d load_feature(const std::string& id) const {
    const auto pose = load_features().find_pose(id);
    if (!pose) throw std::runtime_error("no load feature " + id);
    return *pose;
  }

  const cell::CadFeatures& load_features() const { return cell_file_.require("load", "the closed loop").features; }

  /// The load's pose in the target's frame when inserted (its insertion feature).
  Eigen::Isometry3d insertion_offset() const {
    if (!load_features().insertion) throw std::runtime_error("the load has no insertion feature");
    return load_features().insertion->pose_target_entity;
  }

  /// cell_sim, crane_gateway, vision_tracker and admittance_control with their shipped configurations.
  void start_cell(const std::string& admittance_config = repo_file("deploy/config/admittance_control.json")) {
    const std::string port = std::to_string(free_tcp_port());
    cell_.start("cell_sim", "cell_sim", {"--config", repo_file("deploy/config/cell_sim.json"), "--plc-port", port});
    cell_.start("crane_gateway", "crane_gateway",
                {"--config", repo_file("deploy/config/crane_gateway.json"), "--plc-port", port});
    cell_.start("vision_tracker", "vision_tracker", {"--config", repo_file("deploy/config/vision_tracker.json")});
    cell_.start("admittance_control", "admittance_control", {"--config", admittance_config});
    ASSERT_TRUE(cell_.wait_ready({"cell_sim", "crane_gateway", "vision_tracker", "admittance_control"}, 60s));
    ASSERT_TRUE(cell_.wait_until([&] { return crane_.link_ok && truth_.count("load") && truth_.count("target"); }, 20s))
        << "no crane link or ground truth";
  }

  /// Asks the PLC for external control (the crane then follows rigger/crane/cmd_velocity).
  void take_crane() {
    ASSERT_TRUE(crane_control_writer_->wait_for_readers(1, 5s));
    rigger_crane_CraneControl c{};
    c.header.stamp = dds::wire_now();
    c.seq = 1;
    c.kind = rigger_crane_CRANE_REQUEST_EXTERNAL;
    c.source = const_cast<char*>(kCommanderId);
    crane_control_writer_->write(c);
    ASSERT_TRUE(cell_.wait_until([&] { return crane_.external_control && !crane_.fault; }, 10s))
        << "no external control: " << crane_.fault_text;
  }

  /// The tracker in continuous mode; waits until it reports both objects.
  void start_tracking() {
    ASSERT_TRUE(tracker_command_writer_->wait_for_readers(1, 5s));
    rigger_vision_TrackerCommand c{};
    c.header.stamp = dds::wire_now();
    c.seq = 1;
    c.object_id = const_cast<char*>("");
    c.kind = rigger_vision_TRACK_CONTINUOUS;
    c.source = const_cast<char*>(kCommanderId);
    tracker_command_writer_->write(c);
    ASSERT_TRUE(cell_.wait_until([&] { return tracked_.count("load") && tracked_.count("target"); }, 20s))
        << "the tracker does not see the load and the target";
  }

  /// A Cartesian motion of the tool to `pose_world_tool` (sent in the robot's base frame); waits for its end.
  void move_tool(const std::string& id, const Eigen::Isometry3d& pose_world_tool, double speed, bool must_succeed) {
    ASSERT_TRUE(motion_writer_->wait_for_readers(1, 5s));
    ASSERT_TRUE(motion_status_reader_->wait_for_writers(1, 5s));  // the replies are volatile
    rigger_robot_MotionCommand c{};
    c.header.stamp = dds::wire_now();
    c.header.frame_id = const_cast<char*>("robot");
    c.motion_id = dds::wire_string(id);
    c.seq = ++motion_seq_;
    c.kind = rigger_robot_MOTION_CARTESIAN;
    c.pose_goal = dds::to_wire(pose_world_base_.inverse() * pose_world_tool);
    c.speed_scale = speed;
    c.timeout_s = 30.0;
    c.source = const_cast<char*>(kCommanderId);
    motion_writer_->write(c);
    const auto ended = [&] {
      const auto it = motions_.find(id);
      return it != motions_.end() && it->second.first != rigger_robot_MOTION_ACCEPTED &&
             it->second.first != rigger_robot_MOTION_EXECUTING;
    };
    ASSERT_TRUE(cell_.wait_until(ended, 40s)) << "motion " << id << " did not end";
    if (must_succeed) {
      ASSERT_EQ(motions_[id].first, rigger_robot_MOTION_SUCCEEDED) << "motion " << id << ": " << motions_[id].second;
    }
  }

  /// The robot grips the load on its side (cell file features pre_grasp and grasp_side).
  void attach() {
    const Eigen::Isometry3d pose_world_load = truth_.at("load");
    move_tool("pre_grasp", pose_world_load * load_feature("pre_grasp"), 0.5, true);
    rigger_robot_GripperCommand g{};
    g.header.stamp = dds::wire_now();
    g.seq = 1;
    g.energize = true;
    g.source = const_cast<char*>(kCommanderId);
    ASSERT_TRUE(gripper_writer_->wait_for_readers(1, 5s));
    gripper_writer_->write(g);
    // The load may have swung a little meanwhile: the grasp is computed from where it is now.
    move_tool("grasp", truth_.at("load") * load_feature("grasp_side"), 0.2, false);
    ASSERT_TRUE(cell_.wait_until([&] { return gripper_holding_; }, 10s)) << "the magnet does not hold the load";
  }

  /// Sends an admittance command and waits until the node's state acknowledges it.
  void command(rigger_admittance_AdmittanceMode mode,
               rigger_admittance_ReferenceSource reference = rigger_admittance_REFERENCE_NONE,
               const Eigen::Isometry3d& goal_in_target = Eigen::Isometry3d::Identity(),
               const std::string& source = kCommanderId) {
    if (!admittance_writer_->wait_for_readers(1, 5s)) return;
    rigger_admittance_AdmittanceCommand c{};
    c.header.stamp = dds::wire_now();
    c.seq = ++admittance_seq_;
    c.mode = mode;
    c.reference = reference;
    c.servo_object = const_cast<char*>(reference == rigger_admittance_REFERENCE_VISUAL_SERVO ? "load" : "");
    c.servo_target = const_cast<char*>(reference == rigger_admittance_REFERENCE_VISUAL_SERVO ? "target" : "");
    c.servo_goal_in_target = dds::to_wire(goal_in_target);
    c.source = dds::wire_string(source);
    admittance_writer_->write(c);
    const std::uint64_t seq = admittance_seq_;
    EXPECT_TRUE(cell_.wait_until([&] { return admittance_.last_command_seq == seq; }, 5s));
  }

  Eigen::Vector3d tcp_world() const { return pose_world_base_ * robot_.tool_pose_base.translation(); }
  Eigen::Vector3d tcp_velocity_world() const { return pose_world_base_.linear() * robot_.tool_velocity_base_mps; }

  /// The rope attachment's horizontal offset from the hook (ground truth; the crane frame is the world's).
  Eigen::Vector3d rope_offset_truth() const {
    const Eigen::Isometry3d attachment = load_feature("rope_attachment");
    Eigen::Vector3d offset = (truth_.at("load") * attachment).translation() - crane_.position_m;
    offset.z() = 0.0;
    return offset;
  }

  /// Pushes the load's centre with `push_n` until TCP and crane both travelled `travel_m` along it (at
  /// most 30 s), then removes the push.
  PushResult push_load(const Eigen::Vector3d& push_n, double travel_m);

  /// Called with every ground-truth sample (50 Hz): tests hook their bookkeeping in here.
  void on_truth() {
    if (truth_hook_) truth_hook_();
  }

  std::unique_ptr<SimChannel> sim_;
  std::unique_ptr<dds::Reader<rigger_vision_TrackedPose>> truth_reader_;
  std::unique_ptr<dds::Reader<rigger_vision_TrackedPose>> tracker_reader_;
  std::unique_ptr<dds::Reader<rigger_robot_RobotState>> robot_reader_;
  std::unique_ptr<dds::Reader<rigger_sensing_WrenchStamped>> wrench_reader_;
  std::unique_ptr<dds::Reader<rigger_robot_MotionStatus>> motion_status_reader_;
  std::unique_ptr<dds::Reader<rigger_robot_GripperState>> gripper_reader_;
  std::unique_ptr<dds::Reader<rigger_crane_CraneState>> crane_reader_;
  std::unique_ptr<dds::Reader<rigger_admittance_AdmittanceState>> admittance_reader_;
  std::unique_ptr<dds::Writer<rigger_robot_MotionCommand>> motion_writer_;
  std::unique_ptr<dds::Writer<rigger_robot_GripperCommand>> gripper_writer_;
  std::unique_ptr<dds::Writer<rigger_crane_CraneControl>> crane_control_writer_;
  std::unique_ptr<dds::Writer<rigger_vision_TrackerCommand>> tracker_command_writer_;
  std::unique_ptr<dds::Writer<rigger_admittance_AdmittanceCommand>> admittance_writer_;
  std::unique_ptr<service::ServiceAnnouncer> commander_;
  std::unique_ptr<dds::LivelinessAsserter> liveliness_;

  Eigen::Isometry3d pose_world_base_ = Eigen::Isometry3d::Identity();
  cell::CellFile cell_file_;
  std::map<std::string, Eigen::Isometry3d> truth_;
  std::map<std::string, Eigen::Isometry3d> tracked_;
  RobotView robot_;
  CraneView crane_;
  AdmittanceView admittance_;
  std::map<std::string, std::pair<rigger_robot_MotionState, std::string>> motions_;
  bool gripper_holding_ = false;
  double max_force_n_ = 0.0;
  std::function<void()> truth_hook_;
  std::uint64_t motion_seq_ = 0;
  std::uint64_t admittance_seq_ = 0;
};

/// What a constant push on the load did (ClosedLoopTest::push_load).
struct PushResult {
  bool moved = false;  ///< TCP and crane both travelled the distance along the push
  double took_s = 0.0;
  Eigen::Vector3d tcp_travel = Eigen::Vector3d::Zero(), crane_travel = Eigen::Vector3d::Zero();
  Eigen::Vector3d robot_velocity = Eigen::Vector3d::Zero(), crane_velocity = Eigen::Vector3d::Zero();
  double max_force_n = 0.0;
  double max_rope_offset_m = 0.0;  ///< the largest horizontal offset of the rope attachment from the hook
};

PushResult ClosedLoopTest::push_load(const Eigen::Vector3d& push_n, double travel_m) {
  PushResult r;
  const Eigen::Vector3d direction = push_n.normalized();
  const Eigen::Vector3d tcp0 = tcp_world();
  const Eigen::Vector3d crane0 = crane_.position_m;
  double robot_speed_max = 0.0;
  double crane_speed_max = 0.0;
  truth_hook_ = [&] {
    robot_speed_max = std::max(robot_speed_max, tcp_velocity_world().dot(direction));
    crane_speed_max = std::max(crane_speed_max, crane_.velocity_mps.dot(direction));
    r.max_rope_offset_m = std::max(r.max_rope_offset_m, rope_offset_truth().norm());
  };
  max_force_n_ = 0.0;
  const auto t0 = std::chrono::steady_clock::now();
  const auto ack = sim_->send(rigger_sim_SIM_SET_LOAD_FORCE, true, 0.0, push_n);
  EXPECT_TRUE(ack && ack->first) << (ack ? ack->second : "no answer");
  // Both travel along the push (the robot leads, the crane follows the wrist force and the robot's velocity).
  r.moved = cell_.wait_until(
      [&] {
        return (tcp_world() - tcp0).dot(direction) >= travel_m && (crane_.position_m - crane0).dot(direction) >= travel_m;
      },
      30s);
  r.took_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  r.tcp_travel = tcp_world() - tcp0;
  r.crane_travel = crane_.position_m - crane0;
  r.robot_velocity = tcp_velocity_world();
  r.crane_velocity = crane_.velocity_mps;
  r.max_force_n = max_force_n_;
  truth_hook_ = nullptr;
  sim_->send(rigger_sim_SIM_SET_LOAD_FORCE, true, 0.0, Eigen::Vector3d::Zero());
  std::cout << "push " << push_n.transpose() << " N: after " << r.took_s << " s the TCP moved "
            << 1000.0 * r.tcp_travel.transpose() << " mm, the crane " << 1000.0 * r.crane_travel.transpose()
            << " mm; velocities now: TCP " << r.robot_velocity.transpose() << " m/s, crane "
            << r.crane_velocity.transpose() << " m/s; peak speeds along the push: TCP " << robot_speed_max
            << " m/s, crane " << crane_speed_max << " m/s; max |F| at the wrist " << r.max_force_n
            << " N; max rope offset " << 1000.0 * r.max_rope_offset_m << " mm\n";
  return r;
}

TEST_F(ClosedLoopTest, PushOnTheLoadMovesRobotAndCraneTogether) {
  start_cell();
  take_crane();
  attach();
  command(rigger_admittance_ADMITTANCE_ROBOT_AND_CRANE);
  ASSERT_EQ(admittance_.mode, rigger_admittance_ADMITTANCE_ROBOT_AND_CRANE) << admittance_.fault_text;
  const PushResult r = push_load(Eigen::Vector3d(0.0, 25.0, 0.0), 0.10);
  RecordProperty("push_max_force_n", static_cast<int>(r.max_force_n));
  ASSERT_TRUE(r.moved) << "TCP travel " << r.tcp_travel.transpose() << ", crane travel "
                       << r.crane_travel.transpose() << "; admittance " << admittance_.fault_code << " "
                       << admittance_.fault_text;
  EXPECT_GT(r.robot_velocity.y(), 0.0);
  EXPECT_GT(r.crane_velocity.y(), 0.0);
  EXPECT_LT(r.max_force_n, kForceLimitN);
  EXPECT_FALSE(admittance_.fault) << admittance_.fault_code << ": " << admittance_.fault_text;
  EXPECT_TRUE(gripper_holding_);
}

// The same push with the measured rope offset fed to the crane law (crane.rope_offset_gain_per_s; the
// tracker running continuously): the crane keeps the hook closer above the load (docs/control.md,
// "A person pushes the load").
TEST_F(ClosedLoopTest, PushWithRopeOffsetFeedbackKeepsTheHookCloserAboveTheLoad) {
  nlohmann::json config = nlohmann::json::parse(std::ifstream(repo_file("deploy/config/admittance_control.json")));
  config["cell_file"] = repo_file("deploy/cell/simulated_cell.json");
  config["crane"]["rope_offset_gain_per_s"] = 0.5;
  const std::string config_file = cell_.log_dir() + "/admittance_control.json";
  std::ofstream(config_file) << config.dump(2);
  start_cell(config_file);
  start_tracking();
  take_crane();
  attach();
  command(rigger_admittance_ADMITTANCE_ROBOT_AND_CRANE);
  ASSERT_EQ(admittance_.mode, rigger_admittance_ADMITTANCE_ROBOT_AND_CRANE) << admittance_.fault_text;
  const PushResult r = push_load(Eigen::Vector3d(0.0, 25.0, 0.0), 0.10);
  RecordProperty("push_max_rope_offset_mm", static_cast<int>(1000.0 * r.max_rope_offset_m));
  ASSERT_TRUE(r.moved) << "TCP travel " << r.tcp_travel.transpose() << ", crane travel "
                       << r.crane_travel.transpose() << "; admittance " << admittance_.fault_code << " "
                       << admittance_.fault_text;
  // Without the offset the same push reached 84-86 mm of rope offset and the crane 0.093 m/s
  // (PushOnTheLoadMovesRobotAndCraneTogether, 4 runs); with it 60-62 mm and 0.129-0.132 m/s on a quiet
  // machine, 0.107 m/s once in the loaded parallel suite: the crane bound only asks for faster than without.
  EXPECT_LT(r.max_rope_offset_m, 0.072);
  EXPECT_GT(r.crane_velocity.y(), 0.10);
  EXPECT_LT(r.max_force_n, kForceLimitN);
  EXPECT_FALSE(admittance_.fault) << admittance_.fault_code << ": " << admittance_.fault_text;
}

TEST_F(ClosedLoopTest, VisualServoInsertsTheLoadOntoTheTarget) {
  start_cell();
  take_crane();
  attach();
  start_tracking();
  const Eigen::Isometry3d insertion = insertion_offset();
  const auto truth_error = [&] { return pose_error(truth_.at("load"), truth_.at("target") * insertion); };
  const auto [start_m, start_rad] = truth_error();
  std::cout << "servo start: " << 1000.0 * start_m << " mm, " << start_rad * kRadToDeg << " deg from the goal\n";
  EXPECT_GT(start_m, 0.4);

  max_force_n_ = 0.0;
  const Eigen::Vector3d crane0 = crane_.position_m;
  const auto t0 = std::chrono::steady_clock::now();
  command(rigger_admittance_ADMITTANCE_ROBOT_AND_CRANE, rigger_admittance_REFERENCE_VISUAL_SERVO, insertion);
  ASSERT_EQ(admittance_.mode, rigger_admittance_ADMITTANCE_ROBOT_AND_CRANE) << admittance_.fault_text;
  constexpr double kToleranceM = 0.005;
  constexpr double kToleranceRad = 1.0 / kRadToDeg;
  const bool converged = cell_.wait_until(
      [&] {
        const auto [m, rad] = truth_error();
        return m <= kToleranceM && rad <= kToleranceRad;
      },
      90s);
  const double took_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  const auto [end_m, end_rad] = truth_error();
  std::cout << "servo: true error " << 1000.0 * end_m << " mm, " << end_rad * kRadToDeg << " deg after " << took_s
            << " s (servo's own estimate " << 1000.0 * admittance_.servo_error_m << " mm, "
            << admittance_.servo_error_rad * kRadToDeg << " deg, converged " << admittance_.servo_converged
            << "); max |F| at the wrist " << max_force_n_ << " N\n";
  RecordProperty("servo_time_ms", static_cast<int>(1000.0 * took_s));
  ASSERT_TRUE(converged) << "true error " << 1000.0 * end_m << " mm, " << end_rad * kRadToDeg << " deg; admittance "
                         << admittance_.fault_code << " " << admittance_.fault_text;
  // The skill waits on the node's own convergence: it must come too, and agree with the truth.
  ASSERT_TRUE(cell_.wait_until([&] { return admittance_.servo_converged; }, 20s))
      << "servo error " << admittance_.servo_error_m << " m, " << admittance_.servo_error_rad << " rad";
  const double node_converged_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  // The servo keeps correcting: where it settles (reported, not asserted beyond the tolerance).
  const bool settled = cell_.wait_until([&] { return truth_error().first <= 0.002; }, 15s);
  const double settled_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  const auto [final_m, final_rad] = truth_error();
  const Eigen::Vector3d final_error = (truth_.at("target") * insertion).translation() - truth_.at("load").translation();
  const Eigen::Vector3d crane_travel = crane_.position_m - crane0;
  std::cout << "servo converged (node) after " << node_converged_s << " s; " << (settled ? "" : "not ")
            << "within 2 mm after " << settled_s << " s: true error " << 1000.0 * final_m << " mm ("
            << 1000.0 * final_error.transpose() << " mm), " << final_rad * kRadToDeg << " deg; crane travel "
            << 1000.0 * crane_travel.transpose() << " mm; max |F| at the wrist " << max_force_n_ << " N\n";
  EXPECT_LE(final_m, kToleranceM);
  EXPECT_LE(final_rad, kToleranceRad);
  // The insertion goes down 0.15 m: the hoist took part (hook height down), bridge and trolley followed.
  EXPECT_LT(crane_travel.z(), -0.10);
  EXPECT_GT(crane_travel.y(), 0.30);
  EXPECT_LT(max_force_n_, kForceLimitN);
  EXPECT_FALSE(admittance_.fault) << admittance_.fault_code << ": " << admittance_.fault_text;
  EXPECT_TRUE(gripper_holding_);
}

TEST_F(ClosedLoopTest, LostCommanderStopsTheInsertion) {
  start_cell();
  take_crane();
  attach();
  start_tracking();
  const Eigen::Isometry3d insertion = insertion_offset();
  command(rigger_admittance_ADMITTANCE_ROBOT_AND_CRANE, rigger_admittance_REFERENCE_VISUAL_SERVO, insertion);
  ASSERT_TRUE(cell_.wait_until([&] { return tcp_velocity_world().norm() > 0.03; }, 20s)) << "the servo does not move";
  // The commander leaves: its announcement is unregistered (a SIGKILLed process is seen the same way
  // after its 300 ms liveliness lease).
  commander_.reset();
  ASSERT_TRUE(cell_.wait_until([&] { return admittance_.fault_code == "COMMANDER_LOST"; }, 5s))
      << admittance_.fault_code;
  EXPECT_EQ(admittance_.mode, rigger_admittance_ADMITTANCE_OFF);
  // Robot and crane come to rest (the robot ramps at its acceleration limit, the crane at its own).
  EXPECT_TRUE(
      cell_.wait_until([&] { return tcp_velocity_world().norm() < 0.002 && crane_.velocity_mps.norm() < 0.005; }, 10s))
      << "TCP " << tcp_velocity_world().transpose() << " crane " << crane_.velocity_mps.transpose();
}

TEST_F(ClosedLoopTest, KilledCommanderStopsTheInsertion) {
  RIGGER_REQUIRE_OR_SKIP(access((bin_dir() + "/echo").c_str(), X_OK) == 0, "the echo service is not built");
  expect_clean_exit_ = false;  // the commander is SIGKILLed on purpose
  start_cell();
  // A stand-in for the skill executor: any rigger process announcing the service id the command names.
  const std::string executor = "skill-executor-7";
  cell_.start(executor, "echo", {"--id", executor});
  ASSERT_TRUE(cell_.wait_ready({executor}, 20s));
  take_crane();
  attach();
  start_tracking();
  const Eigen::Isometry3d insertion = insertion_offset();
  command(rigger_admittance_ADMITTANCE_ROBOT_AND_CRANE, rigger_admittance_REFERENCE_VISUAL_SERVO, insertion, executor);
  ASSERT_EQ(admittance_.mode, rigger_admittance_ADMITTANCE_ROBOT_AND_CRANE) << admittance_.fault_text;
  ASSERT_TRUE(cell_.wait_until([&] { return tcp_velocity_world().norm() > 0.05; }, 20s)) << "the servo does not move";
  const auto killed = std::chrono::steady_clock::now();
  ASSERT_TRUE(cell_.process(executor).signal(SIGKILL));
  ASSERT_TRUE(cell_.wait_until([&] { return admittance_.fault_code == "COMMANDER_LOST"; }, 5s))
      << admittance_.fault_code;
  const double lost_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - killed).count();
  EXPECT_EQ(admittance_.mode, rigger_admittance_ADMITTANCE_OFF);
  EXPECT_TRUE(
      cell_.wait_until([&] { return tcp_velocity_world().norm() < 0.002 && crane_.velocity_mps.norm() < 0.005; }, 10s))
      << "TCP " << tcp_velocity_world().transpose() << " crane " << crane_.velocity_mps.transpose();
  const double rest_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - killed).count();
  std::cout << "commander SIGKILLed mid-insertion: COMMANDER_LOST after " << lost_ms
            << " ms, robot and crane at rest after " << rest_ms << " ms\n";
}

}  // namespace
}  // namespace rigger::testing
