// The cell_sim process as a robot driver, gripper and camera would be seen by the rest of rigger
// (acceptance): a twist stream moves the tool, a stale command is ignored, stopping the stream
// stops the arm; the wrist wrench streams at >= 500 Hz; images, camera info, ground truth, motion and
// gripper topics; fault injection is acknowledged; bad configuration exits 2.
#include <algorithm>
#include <cmath>
#include <fstream>
#include <iostream>
#include <limits>
#include <map>
#include <optional>

#include <gtest/gtest.h>
#include <Eigen/Geometry>
#include <nlohmann/json.hpp>

#include "cell_revision_support.hpp"
#include "cell_sim_test_support.hpp"
#include "rigger/dds/qos.hpp"
#include "rigger/dds/sequences.hpp"
#include "rigger/protocol/robot.hpp"
#include "rigger/protocol/sim.hpp"
#include "rigger/protocol/vision.hpp"
#include "rigger/safety/safe_stop.hpp"

namespace rigger::testing {
namespace {

using namespace std::chrono_literals;

struct RobotView {
  WallTime stamp{};
  Eigen::Vector3d tool_position_m = Eigen::Vector3d::Zero();
  Eigen::Vector3d tool_velocity_mps = Eigen::Vector3d::Zero();
  std::uint64_t last_command_seq = 0;
  bool moving = false;
  rigger_robot_RobotMode mode = rigger_robot_ROBOT_IDLE;
};

class CellSimProcessTest : public MultiProcessTest {
 protected:
  void SetUp() override {
    sim_ = std::make_unique<SimChannel>(cell_);
    robot_ = std::make_unique<dds::Reader<rigger_robot_RobotState>>(cell_.participant(), protocol::robot::kState);
    cell_.loop().on_data(*robot_, [this] {
      robot_->take([this](const rigger_robot_RobotState& s, const dds_sample_info_t&) {
        RobotView v;
        v.stamp = dds::to_domain(s.header.stamp);
        v.tool_position_m = dds::to_domain(s.tool_pose).translation();
        v.tool_velocity_mps = dds::to_domain(s.tool_twist).head<3>();
        v.last_command_seq = s.last_command_seq;
        v.moving = s.moving;
        v.mode = s.mode;
        robot_states_.push_back(v);
      });
    });
    twist_ =
        std::make_unique<dds::Writer<rigger_sensing_TwistCommand>>(cell_.participant(), protocol::robot::kCmdTwist);
    cell_.loop().every(10ms, [this] {
      if (twist_velocity_) send_twist(*twist_velocity_, std::chrono::system_clock::now());
    });
  }

  void start(std::vector<std::string> extra = {}) {
    std::vector<std::string> args{"--config", repo_file("deploy/config/cell_sim.json"), "--plc-port",
                                  std::to_string(free_tcp_port())};
    args.insert(args.end(), extra.begin(), extra.end());
    cell_.start("cell_sim", "cell_sim", args);
    ASSERT_TRUE(cell_.wait_ready({"cell_sim"}, 20s));
  }

  void send_twist(const Eigen::Vector3d& linear_mps, WallTime stamp, double timeout_s = 0.1) {
    rigger_sensing_TwistCommand c{};
    c.header.stamp = dds::to_wire(stamp);
    c.header.frame_id = const_cast<char*>("robot");
    c.seq = ++twist_seq_;
    dds::Vector6d twist = dds::Vector6d::Zero();
    twist.head<3>() = linear_mps;
    c.twist = dds::to_wire_twist(twist);
    c.timeout_s = timeout_s;
    c.source = const_cast<char*>("integration-test");
    twist_->write(c);
  }

  const RobotView& robot() const { return robot_states_.back(); }

  std::unique_ptr<SimChannel> sim_;
  std::unique_ptr<dds::Reader<rigger_robot_RobotState>> robot_;
  std::unique_ptr<dds::Writer<rigger_sensing_TwistCommand>> twist_;
  std::vector<RobotView> robot_states_;
  std::optional<Eigen::Vector3d> twist_velocity_;
  std::uint64_t twist_seq_ = 0;
};

TEST_F(CellSimProcessTest, TwistStreamMovesTheToolStaleCommandsAreIgnoredAndStoppingStopsTheArm) {
  start();
  ASSERT_TRUE(twist_->wait_for_readers(1, 5s));
  ASSERT_TRUE(cell_.wait_until([&] { return !robot_states_.empty(); }, 5s));
  const Eigen::Vector3d start_m = robot().tool_position_m;

  // 100 Hz, fresh stamps, 0.1 s timeout: the tool rises.
  twist_velocity_ = Eigen::Vector3d(0.0, 0.0, 0.05);
  ASSERT_TRUE(cell_.wait_until([&] { return robot().tool_position_m.z() > start_m.z() + 0.02; }, 5s))
      << "tool at " << robot().tool_position_m.transpose() << ", started at " << start_m.transpose();
  EXPECT_EQ(robot().mode, rigger_robot_ROBOT_VELOCITY);
  EXPECT_NEAR(robot().tool_velocity_mps.z(), 0.05, 0.01);

  // The stream stops: within its 0.1 s timeout plus the deceleration, the arm is still.
  twist_velocity_.reset();
  const WallTime stream_end = std::chrono::system_clock::now();
  ASSERT_TRUE(
      cell_.wait_until([&] { return robot().stamp > stream_end && robot().tool_velocity_mps.norm() < 1e-3; }, 2s));
  std::cout << "stream stopped: tool still after " << ms_between(stream_end, robot().stamp) << " ms\n";
  const Eigen::Vector3d stopped_at = robot().tool_position_m;
  const std::uint64_t seq_before = robot().last_command_seq;

  // A command older than its timeout (as after a network drop) is ignored, however new its seq.
  for (int i = 0; i < 5; ++i) send_twist({0.0, 0.0, 0.05}, std::chrono::system_clock::now() - 1s);
  const WallTime stale_sent = std::chrono::system_clock::now();
  cell_.wait_until([] { return false; }, 400ms);
  ASSERT_GT(robot().stamp, stale_sent);
  EXPECT_LT((robot().tool_position_m - stopped_at).norm(), 1e-3);
  EXPECT_EQ(robot().last_command_seq, seq_before);

  // A fresh one after them is taken.
  twist_velocity_ = Eigen::Vector3d(0.0, 0.0, -0.05);
  EXPECT_TRUE(cell_.wait_until([&] { return robot().tool_position_m.z() < stopped_at.z() - 0.01; }, 5s));
  twist_velocity_.reset();
}

// The robot driver's side of the software safe stop (rigger/safety/stop): the arm stops at once while
// the twist stream goes on, stays still, and moves again only after the reset.
TEST_F(CellSimProcessTest, SafeStopOfTheRobotStopsTheArmUntilItsReset) {
  // Before any device listens, riggerctl estop says that nothing was stopped (exit 3).
  const auto none = run_riggerctl(cell_, "estop-none", {"estop", "--timeout", "1"});
  EXPECT_EQ(none.code(), 3) << none.output;
  EXPECT_NE(none.output.find("nothing was stopped"), std::string::npos) << none.output;
  start();
  safety::SafeStopWriter stops(cell_.participant());
  ASSERT_TRUE(twist_->wait_for_readers(1, 5s));
  ASSERT_TRUE(stops.writer().wait_for_readers(1, 5s));
  ASSERT_TRUE(cell_.wait_until([&] { return !robot_states_.empty(); }, 5s));
  twist_velocity_ = Eigen::Vector3d(0.0, 0.0, 0.05);
  ASSERT_TRUE(cell_.wait_until([&] { return robot().tool_velocity_mps.z() > 0.04; }, 5s));

  const WallTime stop_at = std::chrono::system_clock::now();
  ASSERT_EQ(stops.command("robot", true, "integration-test", "stop the arm"), DDS_RETCODE_OK);
  ASSERT_TRUE(
      cell_.wait_until([&] { return robot().stamp > stop_at && robot().tool_velocity_mps.norm() < 1e-3; }, 2s))
      << "the arm still moves at " << robot().tool_velocity_mps.norm() << " m/s";
  const double still_after_ms = ms_between(stop_at, robot().stamp);
  std::cout << "safe stop: tool below 1 mm/s " << still_after_ms << " ms after the stop was written\n";
  EXPECT_LT(still_after_ms, 200.0);
  // The stream goes on for 1 s: nothing of it is applied.
  const Eigen::Vector3d held = robot().tool_position_m;
  const WallTime watch_from = std::chrono::system_clock::now();
  cell_.wait_until([] { return false; }, 1s);
  ASSERT_GT(robot().stamp, watch_from);
  EXPECT_LT((robot().tool_position_m - held).norm(), 1e-3) << "the arm moved while stopped";

  // The reset, from the command line: the next fresh commands move it again.
  const auto reset = run_riggerctl(cell_, "estop-reset", {"estop", "--reset", "robot"});
  EXPECT_EQ(reset.code(), 0) << reset.output;
  EXPECT_NE(reset.output.find("safe stop reset: robot (1 device acknowledged"), std::string::npos) << reset.output;
  EXPECT_TRUE(cell_.wait_until([&] { return robot().tool_position_m.z() > held.z() + 0.01; }, 5s));
  twist_velocity_.reset();
}

TEST_F(CellSimProcessTest, WrenchStreamsAtLeast500Hz) {
  start();
  // The writer is best effort, keep-last 1; this reader keeps a deep history, so that a test thread
  // that a busy machine delays does not lose samples in its own history: what is measured is the
  // stream, not how fast this test takes it.
  dds::Qos deep;
  deep.best_effort().keep_last(4000).volatile_durability();
  dds::Reader<rigger_sensing_WrenchStamped> wrench(cell_.participant(), protocol::robot::kWrench, deep);
  std::vector<WallTime> stamps;
  std::string frame;
  cell_.loop().on_data(wrench, [&] {
    wrench.take([&](const rigger_sensing_WrenchStamped& w, const dds_sample_info_t&) {
      stamps.push_back(dds::to_domain(w.header.stamp));
      frame = dds::to_string(w.header.frame_id);
    });
  });
  ASSERT_TRUE(cell_.wait_until([&] { return stamps.size() > 10; }, 5s));
  stamps.clear();
  const auto t0 = std::chrono::steady_clock::now();
  cell_.wait_until([] { return false; }, 2s);  // the measurement window
  const double window_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  const double received_hz = static_cast<double>(stamps.size()) / window_s;
  ASSERT_GT(stamps.size(), 10u) << "the wrench stream stopped";
  std::vector<double> intervals_ms;
  for (std::size_t i = 1; i < stamps.size(); ++i) intervals_ms.push_back(ms_between(stamps[i - 1], stamps[i]));
  std::nth_element(intervals_ms.begin(), intervals_ms.begin() + intervals_ms.size() / 2, intervals_ms.end());
  const double median_ms = intervals_ms[intervals_ms.size() / 2];
  std::cout << "wrench: " << stamps.size() << " samples in " << window_s << " s: " << received_hz
            << " Hz received; median interval between stamps " << median_ms << " ms\n";
  RecordProperty("wrench_hz", static_cast<int>(received_hz));
  EXPECT_GE(received_hz, 500.0);
  EXPECT_EQ(frame, "tool");
  // Paced at real time: over the window, simulated time advances with the wall clock (status stamps
  // are wall time).
  const WallTime window_start = stamps.front();
  const SimStatusView* a = nullptr;
  for (const auto& status : sim_->history())
    if (!a && status.stamp >= window_start) a = &status;
  ASSERT_NE(a, nullptr);
  const SimStatusView& b = sim_->history().back();
  const double rate = (b.sim_time_s - a->sim_time_s) / (ms_between(a->stamp, b.stamp) / 1000.0);
  std::cout << "simulated seconds per wall second: " << rate << "\n";
  EXPECT_NEAR(rate, 1.0, 0.05);
}

TEST_F(CellSimProcessTest, CameraPublishesImagesInfoAndGroundTruth) {
  start();
  dds::Reader<rigger_vision_Image> image(cell_.participant(), protocol::vision::kCameraImage);
  dds::Reader<rigger_vision_CameraInfo> info(cell_.participant(), protocol::vision::kCameraInfo);
  dds::Reader<rigger_vision_TrackedPose> truth(cell_.participant(), protocol::sim::kGroundTruth);
  int images = 0;
  std::uint32_t width = 0, height = 0, step = 0, bytes = 0;
  std::string encoding;
  double mean = 0.0;
  bool stamps_increase = true;
  std::optional<WallTime> last_stamp;
  cell_.loop().on_data(image, [&] {
    image.take([&](const rigger_vision_Image& im, const dds_sample_info_t&) {
      ++images;
      const WallTime stamp = dds::to_domain(im.header.stamp);
      if (last_stamp && !(stamp > *last_stamp)) stamps_increase = false;
      last_stamp = stamp;
      width = im.width;
      height = im.height;
      step = im.step;
      const auto data = dds::elements(im.data);
      bytes = static_cast<std::uint32_t>(data.size());
      encoding = dds::to_string(im.encoding);
      double sum = 0.0;
      for (std::size_t i = 0; i < data.size(); i += 97) sum += data[i];
      mean = sum / (data.size() / 97.0);
    });
  });
  std::optional<std::array<double, 9>> k;
  cell_.loop().on_data(info, [&] {
    info.take([&](const rigger_vision_CameraInfo& ci, const dds_sample_info_t&) {
      k = std::array<double, 9>{};
      std::copy(std::begin(ci.k), std::end(ci.k), k->begin());
    });
  });
  std::map<std::string, Eigen::Vector3d> truths;
  cell_.loop().on_data(truth, [&] {
    truth.take([&](const rigger_vision_TrackedPose& p, const dds_sample_info_t&) {
      EXPECT_EQ(dds::to_string(p.header.frame_id), "world");
      truths[dds::to_string(p.object_id)] = dds::to_domain(p.pose.pose).translation();
    });
  });
  // Every object of the cell file: load, target, part_fixture, part.
  ASSERT_TRUE(cell_.wait_until([&] { return images > 0 && k && truths.size() == 4; }, 10s));
  // The stream goes on, each image stamped after the one before (its rate is cell_sim_rtf_bench's).
  const int first = images;
  EXPECT_TRUE(cell_.wait_until([&] { return images >= first + 10; }, 10s)) << images - first << " more images";
  EXPECT_TRUE(stamps_increase);
  std::cout << "camera: " << width << "x" << height << " " << encoding << "\n";
  EXPECT_EQ(width, 1280u);
  EXPECT_EQ(height, 720u);
  EXPECT_EQ(step, 1280u);
  EXPECT_EQ(bytes, 1280u * 720u);
  EXPECT_EQ(encoding, "mono8");
  EXPECT_GT(mean, 5.0);
  EXPECT_DOUBLE_EQ((*k)[0], 1000.0);  // fx of simulated_cell.json
  EXPECT_DOUBLE_EQ((*k)[2], 640.0);
  // The target stands where the cell file puts it; the load hangs near its configured pose.
  EXPECT_LT((truths["target"] - Eigen::Vector3d(3.55, 2.25, 0.95)).norm(), 1e-6);
  EXPECT_LT((truths["load"] - Eigen::Vector3d(3.55, 1.75, 1.20)).norm(), 0.05);
  // The part of Pick and Place rests on its table (settling into the contact: well under a millimetre).
  EXPECT_LT((truths["part"] - Eigen::Vector3d(3.05, 1.55, 0.66)).norm(), 0.001);
  EXPECT_LT((truths["part_fixture"] - Eigen::Vector3d(2.90, 1.50, 0.60)).norm(), 1e-6);  // static: exact
  EXPECT_EQ(truths.size(), 4u);
}

TEST_F(CellSimProcessTest, MotionAndGripperCommandsAreReported) {
  start();
  dds::Writer<rigger_robot_MotionCommand> motion(cell_.participant(), protocol::robot::kCmdMotion);
  dds::Reader<rigger_robot_MotionStatus> status(cell_.participant(), protocol::robot::kMotionStatus);
  dds::Writer<rigger_robot_GripperCommand> gripper(cell_.participant(), protocol::robot::kGripperCmd);
  dds::Reader<rigger_robot_GripperState> gripper_state(cell_.participant(), protocol::robot::kGripperState);
  std::map<std::string, std::vector<std::pair<rigger_robot_MotionState, std::string>>> motions;
  cell_.loop().on_data(status, [&] {
    status.take([&](const rigger_robot_MotionStatus& s, const dds_sample_info_t&) {
      motions[dds::to_string(s.motion_id)].push_back({s.state, dds::to_string(s.code)});
    });
  });
  bool energized = false;
  std::uint64_t gripper_seq = 0;
  cell_.loop().on_data(gripper_state, [&] {
    gripper_state.take([&](const rigger_robot_GripperState& s, const dds_sample_info_t&) {
      energized = s.energized;
      gripper_seq = s.last_command_seq;
    });
  });
  ASSERT_TRUE(motion.wait_for_readers(1, 5s));
  ASSERT_TRUE(gripper.wait_for_readers(1, 5s));
  // The replies are volatile: cell_sim's status writers must have met our readers before we command.
  ASSERT_TRUE(status.wait_for_writers(1, 5s));
  ASSERT_TRUE(gripper_state.wait_for_writers(1, 5s));
  const auto send_motion = [&](const char* id, rigger_robot_MotionKind kind, std::vector<double> joints,
                               WallTime stamp = std::chrono::system_clock::now()) {
    rigger_robot_MotionCommand c{};
    c.header.stamp = dds::to_wire(stamp);
    c.motion_id = const_cast<char*>(id);
    c.kind = kind;
    dds::wire_sequence(c.joint_goal, joints);
    c.pose_goal.orientation.w = 1.0;
    c.speed_scale = 1.0;
    c.timeout_s = 10.0;
    motion.write(c);
  };
  // The ready pose (A1..A7 = 0, 22.5, 0, -113.8, 0, -46.3, 0 deg) with A1 turned by 5 degrees.
  constexpr double kDeg = 3.14159265358979323846 / 180.0;
  send_motion("turn", rigger_robot_MOTION_JOINT, {5 * kDeg, 22.5 * kDeg, 0, -113.8 * kDeg, 0, -46.3 * kDeg, 0});
  send_motion("short", rigger_robot_MOTION_JOINT, {0.0, 0.0});
  send_motion("old", rigger_robot_MOTION_JOINT, {0, 0, 0, 0, 0, 0, 0}, std::chrono::system_clock::now() - 10s);
  const auto last_state = [&](const std::string& id) {
    return motions[id].empty() ? std::optional<rigger_robot_MotionState>{} : motions[id].back().first;
  };
  ASSERT_TRUE(cell_.wait_until([&] { return last_state("turn") == rigger_robot_MOTION_SUCCEEDED; }, 10s));
  EXPECT_EQ(motions["turn"].front().first, rigger_robot_MOTION_ACCEPTED);
  ASSERT_TRUE(cell_.wait_until([&] { return last_state("short") && last_state("old"); }, 5s));
  EXPECT_EQ(*last_state("short"), rigger_robot_MOTION_FAILED);
  EXPECT_EQ(motions["short"].back().second, "INVALID");
  EXPECT_EQ(*last_state("old"), rigger_robot_MOTION_FAILED);
  EXPECT_EQ(motions["old"].back().second, "STALE");

  rigger_robot_GripperCommand g{};
  g.header.stamp = dds::wire_now();
  g.seq = 42;
  g.energize = true;
  gripper.write(g);
  EXPECT_TRUE(cell_.wait_until([&] { return energized && gripper_seq == 42; }, 5s));
}

// The magnet holds the part (the arm put it on its top face and energized): a cell revision that adds an
// object, which needs the model built anew, is refused by cell_sim with the reason, and the physics gains
// nothing and keeps the part in the magnet.
TEST_F(CellSimProcessTest, ARevisionAddingAnObjectIsRefusedWhileTheMagnetHolds) {
  start();
  dds::Writer<rigger_robot_MotionCommand> motion(cell_.participant(), protocol::robot::kCmdMotion);
  dds::Reader<rigger_robot_MotionStatus> status(cell_.participant(), protocol::robot::kMotionStatus);
  dds::Writer<rigger_robot_GripperCommand> gripper(cell_.participant(), protocol::robot::kGripperCmd);
  dds::Reader<rigger_robot_GripperState> gripper_state(cell_.participant(), protocol::robot::kGripperState);
  dds::Reader<rigger_vision_TrackedPose> truths(cell_.participant(), protocol::sim::kGroundTruth,
                                                dds::qos::sensor_stream().keep_last(16));
  dds::Writer<rigger_world_CellRevision> revisions(cell_.participant(), protocol::world::kCell);
  std::map<std::string, rigger_robot_MotionState> motions;
  cell_.loop().on_data(status, [&] {
    status.take([&](const rigger_robot_MotionStatus& s, const dds_sample_info_t&) {
      motions[dds::to_string(s.motion_id)] = s.state;
    });
  });
  bool holding = false;
  cell_.loop().on_data(gripper_state, [&] {
    gripper_state.take([&](const rigger_robot_GripperState& s, const dds_sample_info_t&) { holding = s.holding; });
  });
  std::map<std::string, Eigen::Vector3d> truth;
  cell_.loop().on_data(truths, [&] {
    truths.take([&](const rigger_vision_TrackedPose& p, const dds_sample_info_t&) {
      truth[dds::to_string(p.object_id)] = dds::to_domain(p.pose.pose).translation();
    });
  });
  ASSERT_TRUE(motion.wait_for_readers(1, 5s));
  ASSERT_TRUE(gripper.wait_for_readers(1, 5s));
  ASSERT_TRUE(status.wait_for_writers(1, 5s));
  // The tool on the part's top face (its centre 6 cm above the part's, 0.72 m): tool z down, tool x along
  // the part's x (the world's -x), first 10 cm above it, then down to 1 mm above it, energized.
  Eigen::Isometry3d tool = Eigen::Isometry3d::Identity();
  tool.linear() << -1, 0, 0, 0, 1, 0, 0, 0, -1;
  const auto move_to = [&](const char* id, double z, double speed) {
    tool.translation() = Eigen::Vector3d(3.05, 1.55, z);
    rigger_robot_MotionCommand c{};
    c.header.stamp = dds::to_wire(std::chrono::system_clock::now());
    c.header.frame_id = const_cast<char*>("world");
    c.motion_id = const_cast<char*>(id);
    c.kind = rigger_robot_MOTION_CARTESIAN;
    c.pose_goal = dds::to_wire(tool);
    c.speed_scale = speed;
    c.timeout_s = 20.0;
    ASSERT_EQ(motion.write(c), DDS_RETCODE_OK);
    ASSERT_TRUE(
        cell_.wait_until([&] { return motions.count(id) && motions[id] > rigger_robot_MOTION_EXECUTING; }, 30s));
    ASSERT_EQ(motions[id], rigger_robot_MOTION_SUCCEEDED) << id;
  };
  ASSERT_NO_FATAL_FAILURE(move_to("above-part", 0.82, 0.5));
  rigger_robot_GripperCommand g{};
  g.header.stamp = dds::wire_now();
  g.seq = 1;
  g.energize = true;
  gripper.write(g);
  ASSERT_NO_FATAL_FAILURE(move_to("on-part", 0.721, 0.1));
  ASSERT_TRUE(cell_.wait_until([&] { return holding; }, 5s)) << "the magnet did not grip the part";

  std::ifstream in(repo_file("deploy/cell/simulated_cell.json"), std::ios::binary);
  nlohmann::json cell = nlohmann::json::parse(in);
  ASSERT_EQ(publish_cell_revision(revisions, 1, cell, nlohmann::json::object()), DDS_RETCODE_OK);
  ASSERT_TRUE(service_detail_says(cell_, "cell_sim", "cell revision 1")) << cell_.logs();
  cell["entities"].push_back(nlohmann::json::parse(R"({"id": "crate", "kind": "object", "parent": "world",
      "pose": {"position_m": [2.77, 1.40, 0.651], "rpy_deg": [0, 0, 0]},
      "model": {"shape": "box", "size_m": [0.1, 0.1, 0.1], "mass_kg": 2.0, "frame": "box centre"}})"));
  ASSERT_EQ(publish_cell_revision(revisions, 2, cell, nlohmann::json::parse(R"({"added":["crate"]})")), DDS_RETCODE_OK);
  ASSERT_TRUE(service_detail_says(cell_, "cell_sim",
                                  "refused cell revision 2: the magnet holds something: the model is built anew only "
                                  "with it empty"))
      << cell_.logs();
  truth.clear();
  ASSERT_TRUE(cell_.wait_until([&] { return truth.count("part") > 0; }, 5s));
  EXPECT_EQ(truth.count("crate"), 0u) << "the refused revision added the crate";
  EXPECT_TRUE(holding) << "the magnet let go of the part";
}

TEST_F(CellSimProcessTest, FaultInjectionIsAcknowledgedAndBadControlsRefused) {
  start();
  const auto weak = sim_->send(rigger_sim_SIM_SET_HOLDING_FORCE, false, 150.0);
  ASSERT_TRUE(weak.has_value());
  EXPECT_TRUE(weak->first) << weak->second;
  const auto bad = sim_->send(rigger_sim_SIM_SET_LOAD_FORCE, false, 0.0,
                              Eigen::Vector3d(std::numeric_limits<double>::quiet_NaN(), 0, 0));
  ASSERT_TRUE(bad.has_value());
  EXPECT_FALSE(bad->first);
  EXPECT_NE(bad->second.find("not finite"), std::string::npos) << bad->second;
  const auto reset = sim_->send(rigger_sim_SIM_RESET, false);
  ASSERT_TRUE(reset.has_value());
  EXPECT_TRUE(reset->first) << reset->second;
  EXPECT_TRUE(cell_.wait_until([&] { return sim_->has_status() && sim_->latest().sim_time_s < 1.0; }, 5s));
}

// `riggerctl sim`, the newcomer's way to break the simulated cell on purpose (docs/getting-started.md).
TEST_F(CellSimProcessTest, RiggerctlSimInjectsFaultsAndSaysWhenThereIsNoSimulator) {
  int runs = 0;
  const auto riggerctl = [&](const std::vector<std::string>& args) {
    return run_riggerctl(cell_, "riggerctl-" + std::to_string(++runs), args);
  };
  const auto none = riggerctl({"sim", "--timeout", "1", "reset"});
  EXPECT_EQ(none.code(), 3) << none.output;
  EXPECT_NE(none.output.find("no simulated cell on domain"), std::string::npos) << none.output;

  start();
  ASSERT_TRUE(cell_.wait_until([&] { return sim_->has_status() && sim_->latest().plc_link_up; }, 10s));
  const auto cut = riggerctl({"sim", "plc-link", "off"});
  EXPECT_EQ(cut.code(), 0) << cut.output;
  EXPECT_TRUE(cell_.wait_until([&] { return !sim_->latest().plc_link_up; }, 5s));
  EXPECT_EQ(riggerctl({"sim", "plc-link", "on"}).code(), 0);
  EXPECT_TRUE(cell_.wait_until([&] { return sim_->latest().plc_link_up; }, 5s));

  EXPECT_EQ(riggerctl({"sim", "holding-force", "10"}).code(), 0);
  EXPECT_TRUE(cell_.wait_until([&] { return std::abs(sim_->latest().gripper_holding_force_n - 10.0) < 1e-9; }, 5s));
  EXPECT_EQ(riggerctl({"sim", "load-force", "0", "20", "0"}).code(), 0);
  EXPECT_TRUE(cell_.wait_until(
      [&] { return (sim_->latest().load_external_force_n - Eigen::Vector3d(0, 20, 0)).norm() < 1e-9; }, 5s));

  // The simulator's refusal and a usage error are told apart, and neither changes anything.
  const auto refused = riggerctl({"sim", "load-force", "0", "nan", "0"});
  EXPECT_EQ(refused.code(), 1) << refused.output;
  EXPECT_NE(refused.output.find("refused load-force"), std::string::npos) << refused.output;
  EXPECT_NE(refused.output.find("not finite"), std::string::npos) << refused.output;
  const auto usage = riggerctl({"sim", "holding-force", "strong"});
  EXPECT_EQ(usage.code(), 2) << usage.output;
  EXPECT_NE(usage.output.find("expected a force in N"), std::string::npos) << usage.output;
  EXPECT_EQ(sim_->latest().load_external_force_n, Eigen::Vector3d(0, 20, 0));

  EXPECT_EQ(riggerctl({"sim", "reset"}).code(), 0);
  EXPECT_TRUE(cell_.wait_until([&] { return sim_->latest().load_external_force_n.isZero(); }, 5s));
}

TEST_F(CellSimProcessTest, BadConfigurationExitsWithCode2NamingTheKey) {
  expect_refused_configuration(cell_, "cell_sim", R"({"plc": {"heartbeat_timeout_ms": 400}})",
                               "/plc/heartbeat_timeout_ms");
  expect_clean_exit_ = false;
}

}  // namespace
}  // namespace rigger::testing
