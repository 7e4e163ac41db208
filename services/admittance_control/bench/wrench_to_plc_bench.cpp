// Latency from a wrench sample to the crane setpoint in the PLC's registers (not a test; run on
// demand; needs the crane_gateway binary in the build's bin/):
//
//   rigger_admittance_wrench_to_plc_bench [--trials N]   (default 30)
//
// The chain is the product's: wrench (1 kHz, DDS) -> admittance_control's robot law (500 Hz) and crane
// law (50 Hz, deploy/config/admittance_control.json) -> rigger/crane/cmd_velocity -> the crane_gateway
// process (50 Hz cycle, deploy/config/crane_gateway.json) -> Modbus TCP -> the PLC's command block.
// The PLC is cell_sim's emulator (rigger_plc_emulator) in this process with ideal drives, scanning
// every 1 ms so that it sees a write within 1 ms; the admittance node runs in this process on a loop
// thread of its own, fed by a wrench stream from another participant.
// Each trial steps the wrench from 0 to 10 N along x at a random phase and measures from the first
// stepped sample's stamp until the PLC's decoded setpoint on the bridge is non-zero; then the force
// goes back to 0 and the setpoint is awaited at rest. Prints p50, p99 and max.
#include <time.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <random>
#include <string>
#include <thread>
#include <vector>

#include "admittance_node.hpp"
#include "rigger/crane_protocol/crane_config.hpp"
#include "rigger/dds/conversions.hpp"
#include "rigger/dds/liveliness.hpp"
#include "rigger/performance/results.hpp"
#include "rigger/plc/kinematic_crane_axes.hpp"
#include "rigger/plc/plc_emulator.hpp"
#include "rigger/protocol/admittance.hpp"
#include "rigger/protocol/crane.hpp"
#include "rigger/protocol/robot.hpp"
#include "rigger/testing/domain.hpp"
#include "rigger/testing/process.hpp"

namespace rigger::control {
namespace {

using namespace std::chrono_literals;

double quantile(std::vector<double> v, double q) {
  if (v.empty()) return 0.0;
  std::sort(v.begin(), v.end());
  return v[static_cast<std::size_t>(std::min<double>(v.size() - 1, q * static_cast<double>(v.size())))];
}

/// The admittance node on a loop thread of its own (as in its process).
class NodeThread {
 public:
  NodeThread(std::uint32_t domain, const std::string& config_path)
      : options_{"admittance_control", domain, config_path, "warn"},
        participant_(domain),
        loop_(participant_),
        announcer_(participant_, options_.id, "admittance_control"),
        liveliness_(participant_, dds::liveliness_lease() / 3, 0ms),  // as run_service asserts it
        context_{options_, null_logger(), participant_, loop_, announcer_, Config::load(config_path)},
        node_(context_) {
    announcer_.announce(service::ServiceStatus::kReady);
    thread_ = std::thread([this] { loop_.run(); });
  }
  ~NodeThread() {
    loop_.stop();
    thread_.join();
  }

 private:
  service::ServiceOptions options_;
  dds::Participant participant_;
  dds::EventLoop loop_;
  service::ServiceAnnouncer announcer_;
  dds::LivelinessAsserter liveliness_;
  service::ServiceContext context_;
  AdmittanceNode node_;
  std::thread thread_;
};

int run(int trials) {
  const std::string source_dir = RIGGER_SOURCE_DIR;
  testing::DomainLease lease;
  // The PLC with ideal drives, the hook above the load's start in the cell.
  plc::PlcEmulatorConfig plc_config;
  plc_config.program.limits = crane::load_crane_limits(source_dir + "/deploy/cell/simulated_cell.json", "crane");
  plc_config.program.heartbeat_timeout = 150ms;
  plc_config.server.port = 0;
  plc::KinematicCraneAxes axes(Eigen::Vector3d(3.55, 1.75, 1.3), 40.0);
  plc::PlcEmulator plc(plc_config, axes);
  plc.start_server();
  plc.start_cycle_thread(1ms, [&axes](std::chrono::nanoseconds dt) { axes.advance(dt); });

  testing::ChildProcess gateway(
      testing::bin_dir() + "/crane_gateway",
      {"--config", source_dir + "/deploy/config/crane_gateway.json", "--plc-port", std::to_string(plc.port()),
       "--domain", std::to_string(lease.id()), "--log-level", "warn"},
      {}, "/tmp/rigger_wrench_to_plc_bench_gateway.log");
  NodeThread node(lease.id(), source_dir + "/deploy/config/admittance_control.json");

  dds::Participant participant(lease.id());
  dds::Writer<rigger_sensing_WrenchStamped> wrench(participant, protocol::robot::kWrench);
  dds::Writer<rigger_robot_RobotState> robot_state(participant, protocol::robot::kState);
  dds::Writer<rigger_admittance_AdmittanceCommand> commands(participant, protocol::admittance::kCommand);
  dds::Writer<rigger_crane_CraneControl> crane_control(participant, protocol::crane::kControl);

  // The wrench stream: 1 kHz, force x from `force_x`; the stamp of the first sample of a step is kept.
  std::atomic<double> force_x{0.0};
  std::atomic<bool> stop{false};
  std::atomic<std::int64_t> step_stamp_ns{0};
  std::thread feeder([&] {
    timespec next{};
    clock_gettime(CLOCK_MONOTONIC, &next);
    double last = 0.0;
    for (std::uint64_t k = 0; !stop.load(); ++k) {
      const double f = force_x.load();
      rigger_sensing_WrenchStamped w{};
      const WallTime now = std::chrono::system_clock::now();
      w.header.stamp = dds::to_wire(now);
      w.header.frame_id = const_cast<char*>("tool");
      w.wrench = dds::to_wire_wrench((dds::Vector6d() << f, 0, 0, 0, 0, 0).finished());
      wrench.write(w);
      if (f != last && f != 0.0) step_stamp_ns = to_unix_ns(now);
      last = f;
      if (k % 10 == 0) {
        rigger_robot_RobotState s{};
        s.header.stamp = dds::to_wire(now);
        s.flange_pose = dds::to_wire(Eigen::Isometry3d::Identity());
        s.tool_pose = s.flange_pose;
        robot_state.write(s);
      }
      next.tv_nsec += 1000000;
      if (next.tv_nsec >= 1000000000) {
        next.tv_nsec -= 1000000000;
        ++next.tv_sec;
      }
      clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &next, nullptr);
    }
  });
  const auto finish = [&](int code) {
    stop = true;
    feeder.join();
    gateway.signal(SIGINT);
    gateway.wait(5s);
    return code;
  };

  // The gateway connects and takes external control; the node goes to ROBOT_AND_CRANE.
  if (!crane_control.wait_for_readers(1, 20s) || !commands.wait_for_readers(1, 5s)) {
    std::fprintf(stderr, "the gateway or the node did not come up (log: %s)\n", gateway.log_path().c_str());
    return finish(1);
  }
  const auto granted = [](const plc::PlcSnapshot& s) { return s.status.flags.external_control_granted; };
  for (int attempt = 0; attempt < 20 && !plc.wait_until(granted, 500ms); ++attempt) {
    rigger_crane_CraneControl c{};
    c.header.stamp = dds::wire_now();
    c.seq = static_cast<std::uint64_t>(attempt + 1);
    c.kind = rigger_crane_CRANE_REQUEST_EXTERNAL;
    c.source = const_cast<char*>("bench");
    crane_control.write(c);
  }
  if (!plc.wait_until(granted, 1s)) {
    std::fprintf(stderr, "no external control at the PLC (gateway log: %s)\n", gateway.log_path().c_str());
    return finish(1);
  }
  rigger_admittance_AdmittanceCommand c{};
  c.header.stamp = dds::wire_now();
  c.seq = 1;
  c.mode = rigger_admittance_ADMITTANCE_ROBOT_AND_CRANE;
  c.reference = rigger_admittance_REFERENCE_NONE;
  commands.write(c);

  const auto bridge_setpoint = [](const plc::PlcSnapshot& s) { return s.command ? s.command->velocity_mps.x() : 0.0; };
  std::mt19937 random(7);
  std::uniform_int_distribution<int> phase_us(0, 20000);
  std::vector<double> latency_ms;
  for (int trial = 0; trial < trials; ++trial) {
    if (!plc.wait_until([&](const plc::PlcSnapshot& s) { return bridge_setpoint(s) == 0.0; }, 10s)) {
      std::fprintf(stderr, "trial %d: the setpoint did not return to zero\n", trial);
      return finish(1);
    }
    std::this_thread::sleep_for(std::chrono::microseconds(20000 + phase_us(random)));  // random phase, a benchmark
    step_stamp_ns = 0;
    force_x = 10.0;
    const bool seen = plc.wait_until([&](const plc::PlcSnapshot& s) { return bridge_setpoint(s) > 0.0; }, 2s);
    const auto seen_at = std::chrono::system_clock::now();
    force_x = 0.0;
    if (!seen || step_stamp_ns.load() == 0) {
      std::fprintf(stderr, "trial %d: no setpoint at the PLC within 2 s\n", trial);
      return finish(1);
    }
    latency_ms.push_back(static_cast<double>(to_unix_ns(seen_at) - step_stamp_ns.load()) / 1e6);
  }
  std::printf("wrench sample -> crane setpoint in the PLC's registers (%d trials, 10 N step):\n", trials);
  std::printf("  p50 %.1f ms  p99 %.1f ms  max %.1f ms  (min %.1f ms)\n", quantile(latency_ms, 0.5),
              quantile(latency_ms, 0.99), *std::max_element(latency_ms.begin(), latency_ms.end()),
              *std::min_element(latency_ms.begin(), latency_ms.end()));
  std::printf("  stages: robot law 500 Hz, crane law 50 Hz, gateway cycle 50 Hz, PLC scan here 1 ms\n");
  finish(0);
  // No same-run reference: the chain's floor is its stages' periods (printed above).
  performance::Report report("rigger_admittance_wrench_to_plc_bench",
                             "A 10 N wrench step -> the crane setpoint in the emulated PLC's registers through "
                             "admittance_control and the crane_gateway process, " +
                                 std::to_string(trials) + " trials at a random phase");
  const std::pair<const char*, double> levels[] = {{"p50", 0.5}, {"p99", 0.99}};
  for (const auto& [level, q] : levels)
    report.add({std::string("wrench -> PLC setpoint ") + level, quantile(latency_ms, q), "ms", "", 0});
  report.add({"wrench -> PLC setpoint max", *std::max_element(latency_ms.begin(), latency_ms.end()), "ms", "", 0});
  report.add({"wrench -> PLC setpoint min", *std::min_element(latency_ms.begin(), latency_ms.end()), "ms", "", 0});
  return performance::save_for_main(report);
}

}  // namespace
}  // namespace rigger::control

int main(int argc, char** argv) {
  int trials = 30;
  for (int i = 1; i + 1 < argc; ++i)
    if (std::strcmp(argv[i], "--trials") == 0) trials = std::max(1, std::atoi(argv[i + 1]));
  try {
    return rigger::control::run(trials);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "bench failed: %s\n", e.what());
    return 1;
  }
}
