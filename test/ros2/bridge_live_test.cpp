// ros2_bridge as a real process on a private DDS domain, with ROS 2 on the other side (docs/ros2.md):
//  - TwistReachesAStandaloneRos2Subscriber: rigger/robot/cmd_twist at 100 Hz through the bridge to a
//    subscriber written with @foxglove/ros2 (live_subscriber.js: TypeScript RTPS, no DDS library, no
//    ROS 2), which must discover the bridge, match its writer, and decode at least 100 samples. Each one
//    must be exactly the command sent with that stamp (clamped where it was too fast); the stale and
//    the non-finite commands must never arrive; they must arrive at more than 40 Hz.
//  - Ros2BridgeLabTest.TwistReachesAStandaloneRos2SubscriberOnAnotherHost: the same exchange and checks
//    across network namespaces: the bridge (and the test's writer) on lab host `rigger`, the subscriber
//    on lab host `ros2` (deploy/lab-hosts), discovery by multicast on their eth0 with the lab's Cyclone
//    configuration (deploy/cyclonedds-lab.xml). Needs root; skipped, saying so, without it.
//  - WrenchFromARos2DriverArrivesConverted: the test plays a ROS 2 force-torque driver (a
//    geometry_msgs/msg/WrenchStamped writer on rt/ft_sensor/wrench, sensor_data QoS, as
//    force_torque_sensor_broadcaster publishes) at 200 Hz; rigger/robot/wrench must carry at least 100
//    of the fresh samples, each exactly as sent, and none of the stale or non-finite ones.
//    (@foxglove/ros2 1.0.8 cannot publish, so the ROS 2 side here is rigger's own ROS 2 types.)
// No sleeps: the test waits on READY, on matching, and on the subscriber's exit.
#include <unistd.h>

#include <cmath>
#include <fstream>
#include <functional>
#include <map>
#include <memory>
#include <set>
#include <sstream>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "rigger/dds/conversions.hpp"
#include "rigger/dds/pubsub.hpp"
#include "rigger/protocol/robot.hpp"
#include "rigger/ros2/conversions.hpp"
#include "rigger/ros2/qos.hpp"
#include "rigger/testing/cell.hpp"
#include "rigger/testing/lab.hpp"
#include "rigger/testing/require.hpp"

namespace rigger::testing {
namespace {

using namespace std::chrono_literals;
using nlohmann::json;

constexpr const char* kBridgeConfig = R"({
  "refusal_log_interval_s": 0.5,
  "wrench": {"topic": "/ft_sensor/wrench", "qos": "sensor_data", "max_age_s": 0.25},
  "twist_command": {"topic": "/servo_node/delta_twist_cmds", "qos": "reliable_default", "max_age_s": 0.25,
                    "max_linear_mps": 0.25, "max_angular_radps": 0.5, "over_limit": "clamp",
                    "frame_id": "base_link", "max_hold_s": 1.0}
})";

std::int64_t stamp_ns(std::int64_t sec, std::uint32_t nanosec) {
  return sec * 1'000'000'000 + nanosec;
}

/// `dds_uri` with the one setting @foxglove/rtps needs from the bridge's Cyclone. @foxglove/rtps 1.6.0 refuses
/// an SEDP publication that carries no PID_RELIABILITY ("failed to parse publication attributes"), although
/// DDSI-RTPS gives a writer's absent reliability as RELIABLE, and Cyclone leaves out every QoS at its
/// default: so no reliable Cyclone writer would be seen. Cyclone's
/// Compatibility/ExplicitlyPublishQosSetToDefault puts them all on the wire (docs/ros2.md).
std::string for_foxglove(const std::string& dds_uri) {
  return dds_uri +
         ",<Compatibility><ExplicitlyPublishQosSetToDefault>true</ExplicitlyPublishQosSetToDefault>"
         "</Compatibility>";
}

/// Starts ros2_bridge with kBridgeConfig on `cell`'s domain, with Cyclone configuration `dds_uri`, and waits
/// for its READY.
void start_bridge(Cell& cell, const std::string& dds_uri) {
  const std::string path = cell.log_dir() + "/ros2_bridge.json";
  std::ofstream(path) << kBridgeConfig;
  cell.start("ros2_bridge", "ros2_bridge", {"--id", "ros2_bridge", "--config", path}, true,
             {{"CYCLONEDDS_URI", for_foxglove(dds_uri)}});
  ASSERT_TRUE(cell.wait_ready({"ros2_bridge"}, 20s));
}

/// Starts live_subscriber.js with `args` (its --domain is added) wherever the test runs it.
using StartSubscriber = std::function<ChildProcess&(const std::vector<std::string>& args)>;

/// The twist exchange of both Twist tests (see the header): writes rigger/robot/cmd_twist at 100 Hz from
/// `cell`'s participant until the subscriber that `start_subscriber` starts has received 100 samples and
/// exited, then checks every sample it decoded against what was sent, and the rate.
void expect_twists_reach_subscriber(Cell& cell, const StartSubscriber& start_subscriber) {
  ASSERT_TRUE(std::string(RIGGER_NODE).size() > 0) << "node not found: install Node 20+, then npm ci in test/ros2";
  dds::Writer<rigger_sensing_TwistCommand> commands(cell.participant(), protocol::robot::kCmdTwist);
  ASSERT_TRUE(commands.wait_for_readers(1, 10s));

  auto& subscriber = start_subscriber({RIGGER_SOURCE_DIR "/test/ros2/live_subscriber.js", "--topic",
                                       "/servo_node/delta_twist_cmds", "--type", "geometry_msgs/msg/TwistStamped",
                                       "--count", "100", "--reliability", "reliable", "--timeout-s", "60"});
  // What was sent, by stamp: the twist the subscriber must see, or none (refused).
  std::map<std::int64_t, std::optional<dds::Vector6d>> sent;
  std::uint64_t seq = 0;
  std::string frame = "tool0";  // replaced by the bridge's frame_id
  std::string source = "bridge_live_test";
  const auto timer = cell.loop().every(10ms, [&] {
    ++seq;
    dds::Vector6d twist;
    twist << 0.0001 * static_cast<double>(seq % 1000), -0.002, 0.0, 0.0, 0.0, 0.01;
    std::optional<dds::Vector6d> expected = twist;
    WallTime stamp = std::chrono::system_clock::now();
    if (seq % 10 == 3) {  // too fast: clamped to 0.25 m/s, direction kept
      twist.head<3>() << 0.3, 0.4, 0.0;
      expected = twist;
      expected->head<3>() << 0.15, 0.2, 0.0;
    } else if (seq % 10 == 5) {  // not finite: refused
      twist(5) = std::nan("");
      expected.reset();
    } else if (seq % 10 == 7) {  // a second old: refused
      stamp -= 1s;
      expected.reset();
    }
    rigger_sensing_TwistCommand c{};
    c.header.stamp = dds::to_wire(stamp);
    c.header.frame_id = dds::wire_string(frame);
    c.seq = seq;
    c.twist = dds::to_wire_twist(twist);
    c.timeout_s = 0.5;
    c.source = dds::wire_string(source);
    sent[stamp_ns(c.header.stamp.sec, c.header.stamp.nanosec)] = expected;
    commands.write(c);
  });
  const bool ended = cell.wait_until([&] { return !subscriber.running(); }, 90s);
  cell.loop().cancel(timer);
  ASSERT_TRUE(ended) << subscriber.log();
  const auto status = subscriber.wait(5s);
  ASSERT_TRUE(status && status->ok()) << subscriber.log();

  std::istringstream lines(subscriber.log());
  std::string line;
  int matched = 0, clamped = 0, zero = 0;
  json done;
  bool saw_publisher = false;
  while (std::getline(lines, line)) {
    if (line.empty() || line[0] != '{') continue;
    const json e = json::parse(line);
    if (e["event"] == "publisher") saw_publisher = true;
    if (e["event"] == "done") done = e;
    if (e["event"] != "sample") continue;
    const json& m = e["msg"];
    EXPECT_EQ(m["header"]["frame_id"], "base_link");
    // @foxglove/ros2's reader decodes builtin_interfaces/Time as {sec, nsec} (its ROS 1 time type).
    const json& st = m["header"]["stamp"];
    const auto t = stamp_ns(st["sec"].get<std::int64_t>(), st.value("nanosec", st.value("nsec", 0u)));
    dds::Vector6d got;
    got << m["twist"]["linear"]["x"].get<double>(), m["twist"]["linear"]["y"].get<double>(),
        m["twist"]["linear"]["z"].get<double>(), m["twist"]["angular"]["x"].get<double>(),
        m["twist"]["angular"]["y"].get<double>(), m["twist"]["angular"]["z"].get<double>();
    const auto it = sent.find(t);
    if (it == sent.end()) {  // the bridge's own zero twist after a stall
      EXPECT_EQ(got, dds::Vector6d::Zero()) << line;
      ++zero;
      continue;
    }
    ASSERT_TRUE(it->second.has_value()) << "a refused command arrived: " << line;
    EXPECT_LT((got - *it->second).norm(), 1e-12) << line;
    ++matched;
    if (it->second->head<3>().norm() > 0.2) ++clamped;
  }
  EXPECT_TRUE(saw_publisher) << "the subscriber never discovered the bridge's writer";
  EXPECT_GE(matched + zero, 100);
  EXPECT_GE(matched, 90);
  EXPECT_GE(clamped, 5);
  // The bridge forwards 8 of every 10 commands sent at 100 Hz: 80 Hz. Under load, well above 40.
  ASSERT_FALSE(done.is_null());
  EXPECT_GT(done["rate_hz"].get<double>(), 40.0) << done.dump();
  std::cout << "received=" << done["received"] << " matched=" << matched << " clamped=" << clamped << " zero=" << zero
            << " seconds=" << done["seconds"] << " rate_hz=" << done["rate_hz"] << " commands_sent=" << seq << "\n";
}

class Ros2BridgeLiveTest : public MultiProcessTest {};

TEST_F(Ros2BridgeLiveTest, TwistReachesAStandaloneRos2Subscriber) {
  start_bridge(cell_, default_dds_config_uri());
  ASSERT_FALSE(HasFatalFailure());
  expect_twists_reach_subscriber(cell_, [this](const std::vector<std::string>& args) -> ChildProcess& {
    return cell_.start("live_subscriber", RIGGER_NODE, args);
  });
}

/// The bridge on lab host `rigger`, the ROS 2 side on lab host `ros2` (see the header). The test process
/// enters host `rigger` before it makes its participant, so its writer and the bridge it starts live
/// there; the subscriber runs on `ros2` through `deploy/lab-hosts exec`. Each test has its own lab
/// (named after its PID) and its own DDS domain; the lab goes whether the test passes, fails or dies.
class Ros2BridgeLabTest : public ::testing::Test {
 protected:
  void SetUp() override {
    RIGGER_REQUIRE_OR_SKIP(geteuid() == 0, "network namespaces need root (CAP_NET_ADMIN): not run");
    lab_ = std::make_unique<Lab>("r" + std::to_string(getpid() % 10000000), std::vector<std::string>{"rigger", "ros2"});
    lab_->enter("rigger");
    setenv("CYCLONEDDS_URI", kLabDds, 1);
    cell_ = std::make_unique<Cell>();
  }
  void TearDown() override {
    if (cell_) {
      const auto report = cell_->stop_all();
      EXPECT_TRUE(report.ok) << report.problems;
      if (HasFailure()) std::cerr << "===== logs (domain " << cell_->domain_id() << ")\n" << cell_->logs();
      cell_.reset();
    }
    if (lab_) {
      EXPECT_EQ(lab_->tear_down(), "");
    }
  }
  static constexpr const char* kLabDds = "file://" RIGGER_SOURCE_DIR "/deploy/cyclonedds-lab.xml";
  std::unique_ptr<Lab> lab_;
  std::unique_ptr<Cell> cell_;
};

TEST_F(Ros2BridgeLabTest, TwistReachesAStandaloneRos2SubscriberOnAnotherHost) {
  start_bridge(*cell_, kLabDds);
  ASSERT_FALSE(HasFatalFailure());
  expect_twists_reach_subscriber(*cell_, [this](std::vector<std::string> args) -> ChildProcess& {
    args.insert(args.begin(), {"exec", "ros2", RIGGER_NODE});
    args.insert(args.end(), {"--address", lab_->address("ros2")});
    return cell_->start("live_subscriber", RIGGER_SOURCE_DIR "/deploy/lab-hosts", args, true, lab_->env());
  });
}

TEST_F(Ros2BridgeLiveTest, WrenchFromARos2DriverArrivesConverted) {
  start_bridge(cell_, default_dds_config_uri());
  ASSERT_FALSE(HasFatalFailure());
  dds::Writer<geometry_msgs_msg_dds__WrenchStamped_> driver(cell_.participant(), "rt/ft_sensor/wrench",
                                                            ros2::qos::sensor_data());
  dds::Reader<rigger_sensing_WrenchStamped> wrench(cell_.participant(), protocol::robot::kWrench);
  ASSERT_TRUE(driver.wait_for_readers(1, 10s));
  ASSERT_TRUE(wrench.wait_for_writers(1, 10s));

  std::map<std::int64_t, std::optional<dds::Vector6d>> sent;
  int fresh_received = 0, refused_received = 0, mismatched = 0, wrong_frame = 0;
  cell_.loop().on_data(wrench, [&] {
    wrench.take([&](const rigger_sensing_WrenchStamped& w, const dds_sample_info_t&) {
      const auto it = sent.find(stamp_ns(w.header.stamp.sec, w.header.stamp.nanosec));
      if (it == sent.end() || !it->second) {
        ++refused_received;
        return;
      }
      if ((dds::to_domain(w.wrench) - *it->second).norm() != 0.0) ++mismatched;
      if (dds::to_string(w.header.frame_id) != "ft_sensor") ++wrong_frame;
      ++fresh_received;
    });
  });
  std::uint64_t k = 0;
  char frame[] = "ft_sensor";
  cell_.loop().every(5ms, [&] {
    ++k;
    dds::Vector6d v;
    v << static_cast<double>(k), -2.5, 9.81, 0.01, -0.02, 0.03 * static_cast<double>(k);
    WallTime stamp = std::chrono::system_clock::now();
    bool fresh = true;
    if (k % 4 == 1) {  // stale: a second old
      stamp -= 1s;
      fresh = false;
    } else if (k % 9 == 2) {  // not finite
      v(4) = std::numeric_limits<double>::infinity();
      fresh = false;
    }
    rigger_sensing_WrenchStamped r{};
    r.header.stamp = dds::to_wire(stamp);
    r.header.frame_id = frame;
    r.wrench = dds::to_wire_wrench(v);
    sent[stamp_ns(r.header.stamp.sec, r.header.stamp.nanosec)] = fresh ? std::optional(v) : std::nullopt;
    driver.write(ros2::to_ros2(r));
  });
  ASSERT_TRUE(cell_.wait_until([&] { return fresh_received >= 150; }, 30s))
      << "fresh_received=" << fresh_received << " sent=" << k;
  EXPECT_EQ(refused_received, 0);
  EXPECT_EQ(mismatched, 0);
  EXPECT_EQ(wrong_frame, 0);
  std::cout << "wrench sent=" << k << " fresh_received=" << fresh_received << "\n";
}

}  // namespace
}  // namespace rigger::testing
