// Round-trip latency of rigger's typed DDS layer (rigger::dds Writer/Reader + EventLoop, in this
// process and in the echo service) next to Cyclone's own ddsperf ping/pong, measured in the same run on
// the same domain configuration, payload size and rate. Targets: p50 ratio <= 1.5, p99 <= 2.
//
//   build/bench/bench_dds_echo [--rate 1000] [--size 64] [--seconds 10]
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "bench_util.hpp"
#include "echo_rtt.hpp"
#include "rigger/testing/cell.hpp"

namespace {

using namespace std::chrono_literals;

struct Options {
  int rate_hz = 1000;
  int size = 64;
  int seconds = 10;
};

Options parse(int argc, char** argv) {
  using rigger::bench::int_option;
  return {int_option(argc, argv, "--rate", 1000), int_option(argc, argv, "--size", 64),
          int_option(argc, argv, "--seconds", 10)};
}

}  // namespace

int main(int argc, char** argv) {
  const Options opt = parse(argc, argv);
  rigger::testing::Cell cell;
  cell.start("echo", "echo", {"--id", "echo", "--log-level", "warn"});
  if (!cell.wait_ready({"echo"}, 10s)) {
    std::fprintf(stderr, "echo did not become ready\n%s", cell.logs().c_str());
    return 1;
  }

  const std::vector<double> rtt_us = rigger::bench::measure_echo_rtt(cell, {opt.rate_hz, opt.size, opt.seconds});
  if (rtt_us.empty()) {
    std::fprintf(stderr, "echo's request reader did not match\n");
    return 1;
  }
  cell.stop_all();

  using rigger::bench::percentile;
  const double r50 = percentile(rtt_us, 0.50), r90 = percentile(rtt_us, 0.90), r99 = percentile(rtt_us, 0.99);
  const auto ref = rigger::bench::run_ddsperf_pingpong(cell.domain_id(), opt.rate_hz, opt.size, opt.seconds, false);
  const auto ref_ws = rigger::bench::run_ddsperf_pingpong(cell.domain_id(), opt.rate_hz, opt.size, opt.seconds, true);
  if (ref.count == 0 || ref_ws.count == 0) {
    std::fprintf(stderr, "could not parse ddsperf output:\n%s\n%s\n", ref.raw.c_str(), ref_ws.raw.c_str());
    return 1;
  }

  std::printf("DDS round trip, %d B payload at %d Hz for %d s, loopback (deploy/cyclonedds.xml), domain %u\n",
              opt.size, opt.rate_hz, opt.seconds, cell.domain_id());
  std::printf("%-42s %10s %10s %10s %8s\n", "", "p50 us", "p90 us", "p99 us", "samples");
  std::printf("%-42s %10.1f %10.1f %10.1f %8zu\n", "rigger typed layer (EventLoop, echo service)", r50, r90, r99,
              rtt_us.size());
  std::printf("%-42s %10.1f %10.1f %10.1f %8llu\n", "ddsperf ping/pong, listener (default)", ref.p50_us, ref.p90_us,
              ref.p99_us, static_cast<unsigned long long>(ref.count));
  std::printf("%-42s %10.1f %10.1f %10.1f %8llu\n", "ddsperf ping/pong, waitset", ref_ws.p50_us, ref_ws.p90_us,
              ref_ws.p99_us, static_cast<unsigned long long>(ref_ws.count));
  std::printf("ratio vs ddsperf listener: p50 %.2f (target <= 1.5)  p99 %.2f (target <= 2)\n", r50 / ref.p50_us,
              r99 / ref.p99_us);
  std::printf("ratio vs ddsperf waitset:  p50 %.2f  p99 %.2f\n", r50 / ref_ws.p50_us, r99 / ref_ws.p99_us);

  rigger::performance::Report report(
      "bench_dds_echo", "DDS round trip of rigger's typed layer through the echo service, " + std::to_string(opt.size) +
                            " B at " + std::to_string(opt.rate_hz) + " Hz for " + std::to_string(opt.seconds) +
                            " s, loopback, next to ddsperf ping/pong at the same rate and payload");
  using rigger::bench::add_quantiles;
  add_quantiles(report, "typed layer round trip", {r50, r90, r99}, "us", "ddsperf listener round trip",
                rigger::bench::round_trip(ref));
  add_quantiles(report, "ddsperf waitset round trip", rigger::bench::round_trip(ref_ws), "us",
                "ddsperf listener round trip", rigger::bench::round_trip(ref));
  return rigger::performance::save_for_main(report);
}
