// The echo round trip of rigger's typed layer with DDS Security off and on, in the same run:
// the same echo service, rate and payload, first on deploy/cyclonedds.xml, then on
// deploy/cyclonedds-secure.xml with a PKI made for the run by deploy/security/make-pki (identities
// "bench" and "echo"; the echo topics fall under the governance's "signed" class: every submessage
// carries a MAC, nothing is encrypted). Prints both and the ratio on/off.
//
//   build/bench/bench_dds_echo_security [--rate 1000] [--size 64] [--seconds 10]
#include <stdlib.h>

#include <cstdio>
#include <map>
#include <memory>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "bench_util.hpp"
#include "echo_rtt.hpp"
#include "rigger/testing/cell.hpp"

namespace {

using rigger::bench::RttFigures;

// One phase: a fresh Cell (its participant reads CYCLONEDDS_URI now), echo started with `echo_env`.
bool phase(const rigger::bench::EchoRun& run, const std::map<std::string, std::string>& echo_env, RttFigures& out) {
  const auto rtt = rigger::bench::measure_echo_phase(
      run,
      [&](rigger::testing::Cell& cell, std::vector<std::string> args) -> rigger::testing::ChildProcess& {
        return cell.start("echo", "echo", std::move(args), true, echo_env);
      },
      "");
  if (rtt.empty()) return false;
  out = rigger::bench::summarize(rtt);
  return true;
}

}  // namespace

int main(int argc, char** argv) {
  using rigger::bench::int_option;
  const rigger::bench::EchoRun run{int_option(argc, argv, "--rate", 1000), int_option(argc, argv, "--size", 64),
                                   int_option(argc, argv, "--seconds", 10)};
  std::unique_ptr<rigger::bench::RunPki> made;
  try {
    made = std::make_unique<rigger::bench::RunPki>();
  } catch (const std::runtime_error& e) {
    std::fprintf(stderr, "%s\n", e.what());
    return 1;
  }
  const std::string pki = made->pki();
  const std::string plain = rigger::testing::default_dds_config_uri();
  const std::string secure = std::string("file://") + RIGGER_SOURCE_DIR + "/deploy/cyclonedds-secure.xml";

  RttFigures off, on;
  setenv("CYCLONEDDS_URI", plain.c_str(), 1);
  if (!phase(run, {{"CYCLONEDDS_URI", plain}}, off)) return 1;
  setenv("CYCLONEDDS_URI", secure.c_str(), 1);
  setenv("RIGGER_SECURITY_DIR", pki.c_str(), 1);
  setenv("RIGGER_IDENTITY", "bench", 1);
  if (!phase(run, {{"CYCLONEDDS_URI", secure}, {"RIGGER_SECURITY_DIR", pki}, {"RIGGER_IDENTITY", "echo"}}, on))
    return 1;
  made.reset();

  std::printf("DDS round trip through the echo service, %d B payload at %d Hz for %d s each, loopback\n", run.size,
              run.rate_hz, run.seconds);
  std::printf("%-44s %10s %10s %10s %8s\n", "", "p50 us", "p90 us", "p99 us", "samples");
  std::printf("%-44s %10.1f %10.1f %10.1f %8zu\n", "security off (deploy/cyclonedds.xml)", off.p50, off.p90, off.p99,
              off.count);
  std::printf("%-44s %10.1f %10.1f %10.1f %8zu\n", "security on (deploy/cyclonedds-secure.xml)", on.p50, on.p90,
              on.p99, on.count);
  std::printf("ratio on/off: p50 %.2f  p90 %.2f  p99 %.2f\n", on.p50 / off.p50, on.p90 / off.p90, on.p99 / off.p99);

  rigger::performance::Report report(
      "bench_dds_echo_security", "DDS round trip through the echo service with DDS Security on (signed), " +
                                     std::to_string(run.size) + " B at " + std::to_string(run.rate_hz) + " Hz for " +
                                     std::to_string(run.seconds) + " s, loopback, next to the same with security off");
  rigger::bench::add_quantiles(report, "round trip, security on", {on.p50, on.p90, on.p99}, "us",
                               "round trip, security off", {off.p50, off.p90, off.p99});
  return rigger::performance::save_for_main(report);
}
