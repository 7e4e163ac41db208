#pragma once
// Small helpers shared by the benchmarks: percentiles and running ddsperf as the DDS reference.
#include <sys/types.h>

#include <cstdint>
#include <functional>
#include <string>
#include <utility>
#include <vector>

#include "rigger/performance/results.hpp"
#include "rigger/testing/process.hpp"

namespace rigger::bench {

/// The q-quantile (0..1) of `values` (nearest rank); 0 when empty.
double percentile(std::vector<double> values, double q);

/// How a cost grew from `first` to `last` while the work grew `scale` times: "1.05x over 10x: flat"
/// (<= 1.2x), "… linear or better" (<= 1.2 x scale) or "… worse than linear".
std::string growth_verdict(double first, double last, double scale);

/// Latency summary as ddsperf prints it for one run: the count-weighted mean of its per-second
/// percentiles, converted to round trips (ddsperf prints half the round trip).
struct DdsperfLatency {
  double p50_us = 0;
  double p90_us = 0;
  double p99_us = 0;
  std::uint64_t count = 0;
  std::string raw;  ///< ddsperf's output, for the report when parsing fails
};

/// p50, p90 and p99 of one sample, in one unit.
struct Quantiles {
  double p50 = 0, p90 = 0, p99 = 0;
};

/// Of `values` (nearest rank); zeros when empty.
Quantiles quantiles(const std::vector<double>& values);

/// ddsperf's round trip in µs, or its one-way figure (half the round trip).
Quantiles round_trip(const DdsperfLatency& ddsperf);
Quantiles one_way(const DdsperfLatency& ddsperf);

/// Adds the figures "`what` p50", "`what` p90" and "`what` p99" in `unit` to `report`, each next to the
/// same quantile of `reference` ("`reference_name` p50", ...), or with no reference when
/// `reference_name` is empty.
void add_quantiles(performance::Report& report, const std::string& what, const Quantiles& q, const std::string& unit,
                   const std::string& reference_name = "", const Quantiles& reference = {});

/// Runs `ddsperf pong` and `ddsperf ping <rate>Hz size <bytes>` for `seconds` on `domain` (loopback
/// configuration from CYCLONEDDS_URI) and returns the round-trip figures. `waitset` selects ddsperf's
/// waitset triggering instead of its default listener triggering.
DdsperfLatency run_ddsperf_pingpong(std::uint32_t domain, int rate_hz, int payload_bytes, int seconds, bool waitset);

/// The integer after `--name` in argv ("--name value" pairs), or `fallback` when absent.
int int_option(int argc, char** argv, const std::string& name, int fallback);
/// The value after `name` on the command line, or `fallback`.
std::string string_option(int argc, char** argv, const std::string& name, const std::string& fallback);

/// Runs a shell command and returns its stdout.
std::string run_command(const std::string& command);

/// A PKI for one run: deploy/security/make-pki with this build's rigger-topic-catalog (every identity of
/// the access table) into a fresh /tmp/rigger-bench-pki-XXXXXX/pki, deleted with the object.
class RunPki {
 public:
  /// @throws std::runtime_error naming what failed (the folder, or the make-pki command).
  RunPki();
  RunPki(const RunPki&) = delete;
  RunPki& operator=(const RunPki&) = delete;
  ~RunPki();
  const std::string& folder() const { return folder_; }  ///< the temporary folder, for files that go with it
  const std::string& pki() const { return pki_; }        ///< its RIGGER_SECURITY_DIR

 private:
  std::string folder_, pki_;
};

/// utime + stime of `pid` in seconds (/proc/PID/stat); the test harness's.
using testing::cpu_seconds;

/// voluntary_ctxt_switches of thread `tid` of `pid`, or -1 when /proc cannot be read.
long long voluntary_switches(pid_t pid, const std::string& tid);

/// Voluntary context switches (wake-ups after a blocking wait) of `pid`'s main thread (a service's
/// work loop) and of all its threads.
std::pair<long long, long long> wake_ups(pid_t pid);

/// CPU seconds per wall second (utime + stime) of each of `pids` while `wait()` runs, followed by the
/// first pid's wake-ups per wall second over the same window: its main thread's, then all its threads'.
std::vector<double> cpu_share(const std::vector<pid_t>& pids, const std::function<void()>& wait);

/// Adds one window of cpu_share() (`share`, for processes named `names` in the order of its pids) to
/// `report`: each process's CPU, but the idle participant's at index `reference`, next to that one's; then
/// the first process's wake-ups per second (its work loop's, all its threads'). Each figure's name ends
/// in ", `window`".
void add_cpu_share(performance::Report& report, const std::vector<std::string>& names, std::size_t reference,
                   const std::vector<double>& share, const std::string& window);

}  // namespace rigger::bench
