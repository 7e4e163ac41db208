#pragma once
// The echo round trip of rigger's typed layer, shared by bench_dds_echo and bench_dds_echo_security:
// requests written from the cell's event loop at a fixed rate to a running echo service, replies taken
// on the same loop, the round trip from each reply's own send stamp.
#include <chrono>
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

}  // namespace rigger::bench
