#pragma once
// The echo round trip of rigger's typed layer, shared by bench_dds_echo, bench_dds_echo_security and
// bench_network_matrix:
// requests written from the cell's event loop at a fixed rate to a running echo service, replies taken
// on the same loop, the round trip from each reply's own send stamp.
#include <chrono>
#include <cstddef>
#include <functional>
#include <string>
#include <vector>

#include "rigger/testing/cell.hpp"

namespace rigger::bench {

struct EchoRun {
  int rate_hz = 1000;
  int size = 64;
  int seconds = 10;
};

/// Round trips in µs to the echo service already READY on `cell`'s domain, after a 1 s warm-up.
/// Empty when echo's request reader did not match within 10 s.
std::vector<double> measure_echo_rtt(rigger::testing::Cell& cell, const EchoRun& run);

/// p50, p90, p99 (nearest rank) and count of latencies, in µs.
struct RttFigures {
  double p50 = 0, p90 = 0, p99 = 0;
  std::size_t count = 0;
};
RttFigures summarize(const std::vector<double>& us);

/// Starts the echo service as process "echo" of `cell` with `args` (its id and log level) and the cell's
/// domain (Cell::start adds it).
using StartEcho =
    std::function<rigger::testing::ChildProcess&(rigger::testing::Cell& cell, std::vector<std::string> args)>;

/// One measurement from scratch: a fresh Cell(`cell_subfolder`) (its participant reads CYCLONEDDS_URI
/// now), echo started by `start_echo` and READY, measure_echo_rtt, echo stopped with SIGINT. The round
/// trips in µs; empty, with what went wrong and echo's log on stderr, when echo did not become ready or
/// did not match.
std::vector<double> measure_echo_phase(const EchoRun& run, const StartEcho& start_echo,
                                       const std::string& cell_subfolder);

}  // namespace rigger::bench
