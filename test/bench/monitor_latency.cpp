// Monitor reaction: a monitor_host process runs a ForceMonitor on a 1 kHz wrench stream
// published here; the force steps above the limit and the time from publishing the first sample of the
// step to receiving the monitor's FAILURE is measured — two DDS hops (wrench, event) plus the filter,
// the check and the host's loop. Printed next to ddsperf's ping/pong round trip (also two hops) from the
// same run.
//
//   build/bench/bench_monitor_latency [--trials 300] [--rate 1000]
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "../integration/skill_command_support.hpp"
#include "bench_util.hpp"
#include "rigger/dds/conversions.hpp"
#include "rigger/dds/pubsub.hpp"
#include "rigger/protocol/robot.hpp"
#include "rigger/protocol/skill.hpp"
#include "rigger/testing/cell.hpp"

namespace {

using namespace std::chrono_literals;
using Clock = std::chrono::steady_clock;

struct Options {
  int trials = 300;
  int rate_hz = 1000;
};

Options parse(int argc, char** argv) {
  using rigger::bench::int_option;
  return {int_option(argc, argv, "--trials", 300), int_option(argc, argv, "--rate", 1000)};
}

}  // namespace

int main(int argc, char** argv) {
  const Options opt = parse(argc, argv);
  rigger::testing::Cell cell;
  cell.start("mh", "monitor_host", {"--id", "mh", "--log-level", "warn"});
  if (!cell.wait_ready({"mh"}, 20s)) {
    std::fprintf(stderr, "monitor_host did not become ready\n%s", cell.logs().c_str());
    return 1;
  }
  namespace dds = rigger::dds;
  auto& p = cell.participant();
  auto& loop = cell.loop();
  dds::Writer<rigger_skill_SkillCommand> commands(p, rigger::protocol::skill::kCommand);
  dds::Reader<rigger_skill_SkillEvent> events(p, rigger::protocol::skill::kEvent);
  dds::Writer<rigger_sensing_WrenchStamped> wrench(p, rigger::protocol::robot::kWrench);
  if (!commands.wait_for_readers(1, 10s) || !wrench.wait_for_readers(1, 10s)) {
    std::fprintf(stderr, "monitor_host not matched\n");
    return 1;
  }

  // Per trial: START, 50 samples below the limit (armed), step, wait for the FAILURE, back down.
  enum class Phase { kStart, kArming, kStepped, kDone };
  Phase phase = Phase::kStart;
  int trial = 0, samples_in_phase = 0, wrong = 0;
  double force_n = 5.0;
  Clock::time_point step_sent{};
  std::vector<double> latency_us;
  std::uint64_t seq = 0;
  std::string node;

  loop.on_data(events, [&] {
    events.take([&](const rigger_skill_SkillEvent& e, const dds_sample_info_t&) {
      if (e.kind == rigger_skill_SKILL_EVENT_ACCEPTED) return;  // the host's answer to the START
      if (dds::to_string(e.node_id) != node || phase != Phase::kStepped) {
        ++wrong;  // fired before the step, or a stale event
        return;
      }
      if (e.kind == rigger_skill_SKILL_EVENT_FAILURE && dds::to_string(e.code) == "FORCE_LIMIT")
        latency_us.push_back(std::chrono::duration<double, std::micro>(Clock::now() - step_sent).count());
      else ++wrong;
      force_n = 5.0;
      phase = ++trial >= opt.trials ? Phase::kDone : Phase::kStart;
    });
  });
  loop.every(std::chrono::nanoseconds(1'000'000'000 / opt.rate_hz), [&] {
    if (phase == Phase::kStart) {
      node = "force-" + std::to_string(trial);
      rigger::testing::write_skill_command(commands, {"mh", "bench", node, "ForceMonitor", rigger_skill_SKILL_START,
                                                      R"({"max_force_n": 50, "dwell_s": 0, "cutoff_hz": 500})", "", ++seq});
      phase = Phase::kArming;
      samples_in_phase = 0;
    } else if (phase == Phase::kArming && ++samples_in_phase >= 50) {
      force_n = 200.0;
      phase = Phase::kStepped;
      step_sent = Clock::now();
    }
    rigger_sensing_WrenchStamped w{};
    w.header.stamp = dds::wire_now();
    w.wrench.force.z = force_n;
    wrench.write(w);
  });
  loop.run_until([&] { return phase == Phase::kDone; }, std::chrono::seconds(10 + opt.trials / 5));
  cell.stop_all();

  using rigger::bench::percentile;
  const auto ref = rigger::bench::run_ddsperf_pingpong(cell.domain_id(), opt.rate_hz, 128, 10, true);
  if (ref.count == 0) {
    std::fprintf(stderr, "could not parse ddsperf output:\n%s\n", ref.raw.c_str());
    return 1;
  }
  std::printf("Force step published -> ForceMonitor FAILURE received, %d Hz wrench stream, %zu of %d trials, loopback\n",
              opt.rate_hz, latency_us.size(), opt.trials);
  std::printf("%-48s %10s %10s %10s %8s\n", "", "p50 us", "p90 us", "p99 us", "samples");
  std::printf("%-48s %10.1f %10.1f %10.1f %8zu\n", "wrench -> monitor_host -> SkillEvent (2 hops)",
              percentile(latency_us, 0.5), percentile(latency_us, 0.9), percentile(latency_us, 0.99), latency_us.size());
  std::printf("%-48s %10.1f %10.1f %10.1f %8llu\n", "ddsperf ping/pong 128 B, waitset (2 hops)", ref.p50_us,
              ref.p90_us, ref.p99_us, static_cast<unsigned long long>(ref.count));
  std::printf("%-48s %10.1f %10.1f %10.1f\n", "  one-way floor (half of it)", ref.p50_us / 2, ref.p90_us / 2,
              ref.p99_us / 2);
  std::printf("unexpected events: %d\n", wrong);
  if (wrong != 0 || static_cast<int>(latency_us.size()) != opt.trials) return 1;

  rigger::performance::Report report(
      "bench_monitor_latency", "Force step published -> ForceMonitor FAILURE received through monitor_host (2 hops), " +
                                   std::to_string(opt.rate_hz) + " Hz wrench stream, " + std::to_string(opt.trials) +
                                   " trials, loopback, next to ddsperf ping/pong 128 B (waitset, 2 hops)");
  rigger::bench::add_quantiles(report, "wrench step -> FAILURE", rigger::bench::quantiles(latency_us), "us",
                               "ddsperf waitset round trip", rigger::bench::round_trip(ref));
  return rigger::performance::save_for_main(report);
}
