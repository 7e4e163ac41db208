// Gateway cycle round trip next to the raw libmodbus floor, against the same PLC emulator in
// the same run: one status-block read plus one command-block write each.
//
//   rigger_crane_gateway_bench [--benchmark_min_time=...]
// prints both, then the ratio (target <= 1.3).
#include <benchmark/benchmark.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <map>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include "crane_gateway.hpp"
#include "rigger/crane_protocol/testing.hpp"
#include "rigger/plc/kinematic_crane_axes.hpp"
#include "rigger/plc/plc_emulator.hpp"

namespace {

using ::rigger::crane::testing::reference_limits;

using namespace std::chrono_literals;
using namespace rigger;
namespace reg = crane::reg;

// The emulated PLC (cycling at 250 Hz on its own thread), a connected gateway holding external
// control, and a raw libmodbus client.
struct Rig {
  Rig() : axes({4.0, 2.5, 2.0}, 40.0) {
    plc::PlcEmulatorConfig plc_config;
    plc_config.program.limits = reference_limits();
    plc_config.server.port = 0;
    emulator = std::make_unique<plc::PlcEmulator>(plc_config, axes);
    emulator->start_server();
    emulator->start_cycle_thread(4ms, [this](std::chrono::nanoseconds dt) { axes.advance(dt); });

    crane_gateway::CraneGatewayConfig config;
    config.plc_port = emulator->port();
    config.logic.plausibility.limits = reference_limits();
    gateway = std::make_unique<crane_gateway::CraneGateway>(config);
    gateway->set_control({true, true});
    for (int i = 0; i < 100 && !gateway->state().external_control_granted; ++i) {
      gateway->cycle();
      emulator->wait_until(
          [](const plc::PlcSnapshot& s) { return s.status.flags.external_control_granted; }, 20ms);
    }
    gateway->cycle();
    if (!gateway->state().external_control_granted) {
      throw std::runtime_error("no grant: " + gateway->state().fault_reason);
    }

    raw = crane::make_tcp_client("127.0.0.1", emulator->port(), 50ms);
    if (modbus_connect(raw.get()) != 0) {
      throw std::runtime_error("raw client cannot connect");
    }
  }

  plc::KinematicCraneAxes axes;
  std::unique_ptr<plc::PlcEmulator> emulator;
  std::unique_ptr<crane_gateway::CraneGateway> gateway;
  crane::ModbusContextPtr raw;
};

Rig& rig() {
  static Rig instance;
  return instance;
}

// One raw round trip: the status block read and the command block write the gateway does,
// with the block the gateway writes while holding the crane with zero setpoints.
bool raw_round_trip(modbus_t* client, std::uint16_t heartbeat) {
  crane::CraneCommand command;
  command.control.enable = true;
  command.control.external_control_request = true;
  command.requested_mode = crane::CraneMode::kExternalVelocity;
  command.gateway_heartbeat = heartbeat;
  crane::StatusRegisters status{};
  if (modbus_read_registers(client, reg::kStatusBlockStart, reg::kStatusBlockCount,
                            status.data()) != reg::kStatusBlockCount) {
    return false;
  }
  benchmark::DoNotOptimize(status);
  const auto registers = crane::encode_command(command).registers;
  return modbus_write_registers(client, reg::kCommandBlockStart, reg::kCommandBlockCount,
                                registers.data()) == reg::kCommandBlockCount;
}

void BM_RawModbusRoundTrip(benchmark::State& state) {
  modbus_t* const client = rig().raw.get();
  std::uint16_t heartbeat = 0;
  for (auto _ : state) {
    if (!raw_round_trip(client, ++heartbeat)) {
      state.SkipWithError("raw round trip failed");
      break;
    }
  }
}

void BM_GatewayCycle(benchmark::State& state) {
  crane_gateway::CraneGateway& gateway = *rig().gateway;
  std::int64_t link_lost = 0;
  for (auto _ : state) {
    const auto report = gateway.cycle();
    if (report.outcome == crane_gateway::CycleOutcome::kLinkLost ||
        report.outcome == crane_gateway::CycleOutcome::kConnectFailed) {
      ++link_lost;
    }
    benchmark::DoNotOptimize(report);
  }
  state.counters["link_lost"] = static_cast<double>(link_lost);
}

BENCHMARK(BM_RawModbusRoundTrip)->UseRealTime()->Repetitions(5)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_GatewayCycle)->UseRealTime()->Repetitions(5)->Unit(benchmark::kMicrosecond);

// Keeps the median of each benchmark to print the ratio at the end.
class RatioReporter : public benchmark::ConsoleReporter {
 public:
  void ReportRuns(const std::vector<Run>& runs) override {
    for (const Run& run : runs) {
      if (run.run_type == Run::RT_Aggregate && run.aggregate_name == "median") {
        medians_us[run.run_name.function_name] = run.GetAdjustedRealTime();
      }
    }
    ConsoleReporter::ReportRuns(runs);
  }
  std::map<std::string, double> medians_us;
};

double median_us(std::vector<double> samples) {
  std::sort(samples.begin(), samples.end());
  return samples.empty() ? 0.0 : samples[samples.size() / 2];
}

// Raw and gateway round trips alternated one by one, so that both see the same machine load;
// the medians of single round trips shrug off scheduling spikes.
void paired_comparison(int pairs) {
  Rig& r = rig();
  std::vector<double> raw_us;
  std::vector<double> gateway_us;
  raw_us.reserve(static_cast<std::size_t>(pairs));
  gateway_us.reserve(static_cast<std::size_t>(pairs));
  using Clock = std::chrono::steady_clock;
  std::uint16_t heartbeat = 0;
  for (int i = 0; i < pairs; ++i) {
    const auto t0 = Clock::now();
    const bool raw_ok = raw_round_trip(r.raw.get(), ++heartbeat);
    const auto t1 = Clock::now();
    const auto report = r.gateway->cycle();
    const auto t2 = Clock::now();
    if (raw_ok) raw_us.push_back(std::chrono::duration<double, std::micro>(t1 - t0).count());
    if (report.outcome != crane_gateway::CycleOutcome::kLinkLost &&
        report.outcome != crane_gateway::CycleOutcome::kConnectFailed &&
        report.outcome != crane_gateway::CycleOutcome::kWaitingToReconnect) {
      gateway_us.push_back(std::chrono::duration<double, std::micro>(t2 - t1).count());
    }
  }
  const double raw = median_us(raw_us);
  const double gateway = median_us(gateway_us);
  std::printf(
      "\npaired, %d alternating round trips (median of single round trips):\n"
      "  raw libmodbus read+write: %.1f us (%zu ok)\n"
      "  gateway cycle:            %.1f us (%zu ok)\n"
      "  ratio: %.2f (target <= 1.30) %s\n",
      pairs, raw, raw_us.size(), gateway, gateway_us.size(), raw > 0 ? gateway / raw : 0.0,
      raw > 0 && gateway / raw <= 1.3 ? "OK" : "ABOVE TARGET");
}

}  // namespace

int main(int argc, char** argv) {
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) {
    return 1;
  }
  try {
    rig();
  } catch (const std::exception& e) {
    std::fprintf(stderr, "setup failed: %s\n", e.what());
    return 1;
  }
  RatioReporter reporter;
  benchmark::RunSpecifiedBenchmarks(&reporter);
  const auto raw = reporter.medians_us.find("BM_RawModbusRoundTrip");
  const auto cycle = reporter.medians_us.find("BM_GatewayCycle");
  if (raw != reporter.medians_us.end() && cycle != reporter.medians_us.end() && raw->second > 0) {
    const double ratio = cycle->second / raw->second;
    std::printf(
        "\nGoogle Benchmark medians of 5 repetitions (sequential, sensitive to load drift):\n"
        "  raw libmodbus read+write: %.1f us\n"
        "  gateway cycle:            %.1f us\n"
        "  ratio: %.2f\n",
        raw->second, cycle->second, ratio);
  }
  paired_comparison(5000);
  benchmark::Shutdown();
  return 0;
}
