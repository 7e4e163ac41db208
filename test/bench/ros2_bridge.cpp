// What the ROS 2 bridge adds to a wrench on its way from a ROS 2 driver into rigger: a
// geometry_msgs/WrenchStamped written on the driver's DDS topic (rt/…, sensor_data QoS) goes through the
// ros2_bridge process (age and finiteness checks, conversion) and arrives as rigger/robot/wrench. Measured
// from the sample's stamp to its arrival back in this process: two DDS hops and the bridge. The same-run
// reference is the echo service's round trip at the same rate: two DDS hops through another process that
// does nothing but copy. Both use loopback with deploy/cyclonedds.xml.
//
//   build/bench/bench_ros2_bridge [--rate 500] [--seconds 10]
#include <cstdio>
#include <map>
#include <string>
#include <vector>

#include "bench_util.hpp"
#include "echo_rtt.hpp"
#include "rigger/dds/conversions.hpp"
#include "rigger/dds/pubsub.hpp"
#include "rigger/idl/types.hpp"
#include "rigger/protocol/robot.hpp"
#include "rigger/ros2/conversions.hpp"
#include "rigger/ros2/qos.hpp"
#include "rigger/ros2/types.hpp"
#include "rigger/testing/cell.hpp"

namespace {

using namespace std::chrono_literals;
using Clock = std::chrono::system_clock;

struct BridgeRun {
  std::vector<double> latency_us;
  std::uint64_t sent = 0;
};

/// Wrenches at `rate_hz` for `seconds` (after a 1 s warm-up), each stamped when written and numbered in its
/// torque.z; the latency of each one that comes back as rigger/robot/wrench.
BridgeRun measure_bridge(rigger::testing::Cell& cell, const std::string& ros2_topic, int rate_hz, int seconds) {
  rigger::dds::Writer<geometry_msgs_msg_dds__WrenchStamped_> ros2(cell.participant(), ros2_topic,
                                                                 rigger::ros2::qos::sensor_data());
  rigger::dds::Reader<rigger_sensing_WrenchStamped> rigger_side(cell.participant(), rigger::protocol::robot::kWrench);
  BridgeRun run;
  if (!ros2.wait_for_readers(1, 10s) || !rigger_side.wait_for_writers(1, 10s)) return run;
  struct Sent {
    Clock::time_point at;
    bool measured;  ///< written inside the measuring window
  };
  std::map<std::uint64_t, Sent> in_flight;
  std::uint64_t seq = 0;
  bool measuring = false;
  cell.loop().on_data(rigger_side, [&] {
    const Clock::time_point now = Clock::now();
    rigger_side.take([&](const rigger_sensing_WrenchStamped& w, const dds_sample_info_t&) {
      const auto it = in_flight.find(static_cast<std::uint64_t>(w.wrench.torque.z));
      if (it == in_flight.end()) return;
      if (it->second.measured)
        run.latency_us.push_back(std::chrono::duration<double, std::micro>(now - it->second.at).count());
      in_flight.erase(it);
    });
  });
  const auto timer = cell.loop().every(std::chrono::nanoseconds(1'000'000'000 / rate_hz), [&] {
    rigger_sensing_WrenchStamped w{};
    const Clock::time_point now = Clock::now();
    w.header.stamp = rigger::dds::to_wire(now);
    w.header.frame_id = const_cast<char*>("tool0");
    w.wrench.force.z = -9.81;
    w.wrench.torque.z = static_cast<double>(++seq);
    in_flight[seq] = {now, measuring};
    if (measuring) ++run.sent;
    ros2.write(rigger::ros2::to_ros2(w));  // as the driver's broadcaster writes it
    // Anything older than a second is lost (best effort): forget it.
    while (!in_flight.empty() && now - in_flight.begin()->second.at > 1s) in_flight.erase(in_flight.begin());
  });
  cell.wait_until([] { return false; }, 1s);  // warm-up
  measuring = true;
  cell.wait_until([] { return false; }, std::chrono::seconds(seconds));
  measuring = false;
  cell.loop().cancel(timer);
  cell.wait_until([] { return false; }, 200ms);  // the last ones still on their way
  return run;
}

void print_row(const char* what, const std::vector<double>& us, const std::string& extra) {
  using rigger::bench::percentile;
  std::printf("%-44s %9.1f %9.1f %9.1f %8zu  %s\n", what, percentile(us, 0.5), percentile(us, 0.9), percentile(us, 0.99),
              us.size(), extra.c_str());
}

}  // namespace

int main(int argc, char** argv) {
  const int rate_hz = rigger::bench::int_option(argc, argv, "--rate", 500);
  const int seconds = rigger::bench::int_option(argc, argv, "--seconds", 10);
  rigger::testing::Cell cell;
  cell.start("ros2_bridge", "ros2_bridge",
             {"--id", "ros2_bridge", "--config", std::string(RIGGER_SOURCE_DIR) + "/deploy/config/ros2_bridge.json",
              "--log-level", "warn"});
  cell.start("echo", "echo", {"--id", "echo", "--log-level", "warn"});
  if (!cell.wait_ready({"ros2_bridge", "echo"}, 10s)) {
    std::fprintf(stderr, "the bridge or echo did not become ready\n%s", cell.logs().c_str());
    return 1;
  }
  // The shipped configuration's force-torque broadcaster topic, as the bridge's own test reads it.
  const BridgeRun bridge = measure_bridge(cell, "rt/force_torque_sensor_broadcaster/wrench", rate_hz, seconds);
  if (bridge.latency_us.empty()) {
    std::fprintf(stderr, "no wrench came through the bridge\n%s", cell.logs().c_str());
    return 1;
  }
  const std::vector<double> echo_us = rigger::bench::measure_echo_rtt(cell, {rate_hz, 64, seconds});
  if (echo_us.empty()) {
    std::fprintf(stderr, "echo's request reader did not match\n");
    return 1;
  }
  cell.stop_all();

  std::printf("Wrench through the ROS 2 bridge vs the echo round trip, %d Hz for %d s, loopback, domain %u\n", rate_hz,
              seconds, cell.domain_id());
  std::printf("%-44s %9s %9s %9s %8s\n", "", "p50 us", "p90 us", "p99 us", "samples");
  char lost[64];
  std::snprintf(lost, sizeof lost, "(%llu sent, %.2f %% lost)", static_cast<unsigned long long>(bridge.sent),
                bridge.sent == 0 ? 0.0 : 100.0 * (1.0 - double(bridge.latency_us.size()) / double(bridge.sent)));
  print_row("rt/ wrench -> ros2_bridge -> rigger/robot/wrench", bridge.latency_us, lost);
  print_row("echo round trip (reference: two hops, a copy)", echo_us, "");
  using rigger::bench::percentile;
  std::printf("bridge / echo: p50 %.2f  p99 %.2f; median difference %+.1f us\n",
              percentile(bridge.latency_us, 0.5) / percentile(echo_us, 0.5),
              percentile(bridge.latency_us, 0.99) / percentile(echo_us, 0.99),
              percentile(bridge.latency_us, 0.5) - percentile(echo_us, 0.5));

  rigger::performance::Report report(
      "bench_ros2_bridge",
      "A ROS 2 wrench (rt/, sensor_data) through ros2_bridge to rigger/robot/wrench, " + std::to_string(rate_hz) +
          " Hz for " + std::to_string(seconds) +
          " s, loopback, next to the echo service's round trip at the same rate (two hops, a copy)");
  rigger::bench::add_quantiles(report, "wrench through the bridge", rigger::bench::quantiles(bridge.latency_us), "us",
                               "echo round trip", rigger::bench::quantiles(echo_us));
  report.add({"wrenches lost through the bridge",
              bridge.sent == 0 ? 0.0 : 100.0 * (1.0 - double(bridge.latency_us.size()) / double(bridge.sent)), "%", "",
              0});
  return rigger::performance::save_for_main(report);
}
