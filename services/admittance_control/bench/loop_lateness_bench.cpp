// Wake-up lateness of the admittance node's control loop (not a test; run on demand):
//
//   rigger_admittance_loop_bench [--seconds N]   (default 10 s per measurement)
//
// The node runs in-process on its EventLoop, in mode ROBOT, fed like in the cell: a wrench sample
// every 1 ms and a robot state every 10 ms from another thread (another participant, so the samples
// cross Cyclone's loopback path). A probe timer with the robot loop's period (2 ms) is added to the
// same loop right after the node's: its lateness (wake-up time minus its drift-free deadline) is what
// the node's 500 Hz step sees, plus the step itself (the probe runs after it when both are due).
// The same run also measures a bare timed loop, clock_nanosleep(TIMER_ABSTIME) every 2 ms on the same
// thread, while the same wrench stream keeps running: the floor the machine offers. The two take turns
// in 1 s slices, so that both see the same machine (a build starting halfway skews neither alone).
// Prints p50, p99, p99.9 and max of both, in microseconds, and the p99.9 ratio.
#include <time.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <string>
#include <thread>
#include <vector>

#include "admittance_node.hpp"
#include "rigger/dds/conversions.hpp"
#include "rigger/performance/results.hpp"
#include "rigger/protocol/admittance.hpp"
#include "rigger/protocol/robot.hpp"
#include "rigger/testing/domain.hpp"

namespace rigger::control {
namespace {

using Clock = std::chrono::steady_clock;
constexpr std::chrono::nanoseconds kPeriod = std::chrono::milliseconds(2);

double quantile(std::vector<double> v, double q) {
  if (v.empty()) return 0.0;
  std::sort(v.begin(), v.end());
  const auto index = static_cast<std::size_t>(std::min<double>(v.size() - 1, q * static_cast<double>(v.size())));
  return v[index];
}

void print(const char* name, const std::vector<double>& us) {
  std::printf("%-44s n=%7zu  p50 %7.1f us  p99 %7.1f us  p99.9 %7.1f us  max %8.1f us\n", name, us.size(),
              quantile(us, 0.5), quantile(us, 0.99), quantile(us, 0.999),
              us.empty() ? 0.0 : *std::max_element(us.begin(), us.end()));
}

timespec to_timespec(std::chrono::nanoseconds t) {
  timespec ts{};
  ts.tv_sec = static_cast<time_t>(t.count() / 1000000000);
  ts.tv_nsec = static_cast<long>(t.count() % 1000000000);
  return ts;
}

// A wrench every 1 ms and a robot state every 10 ms until `stop` (absolute-deadline sleeps).
void feed(std::uint32_t domain, const std::atomic<bool>& stop) {
  dds::Participant participant(domain);
  dds::Writer<rigger_sensing_WrenchStamped> wrench(participant, protocol::robot::kWrench);
  dds::Writer<rigger_robot_RobotState> state(participant, protocol::robot::kState);
  timespec next{};
  clock_gettime(CLOCK_MONOTONIC, &next);
  for (std::uint64_t k = 0; !stop.load(); ++k) {
    rigger_sensing_WrenchStamped w{};
    w.header.stamp = dds::wire_now();
    w.header.frame_id = const_cast<char*>("tool");
    w.wrench =
        dds::to_wire_wrench((dds::Vector6d() << 5.0 + 0.1 * static_cast<double>(k % 7), 0, 0, 0, 0, 0).finished());
    wrench.write(w);
    if (k % 10 == 0) {
      rigger_robot_RobotState s{};
      s.header.stamp = dds::wire_now();
      s.flange_pose = dds::to_wire(Eigen::Isometry3d::Identity());
      s.tool_pose = s.flange_pose;
      state.write(s);
    }
    next.tv_nsec += 1000000;
    if (next.tv_nsec >= 1000000000) {
      next.tv_nsec -= 1000000000;
      ++next.tv_sec;
    }
    clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &next, nullptr);
  }
}

// The node on its EventLoop, in mode ROBOT, with a probe timer; measure(slice) records the probe's
// lateness for one slice and appends it to `lateness_us`.
class NodeLoop {
 public:
  explicit NodeLoop(std::uint32_t domain)
      : options_{"admittance-bench", domain, "", "warn"},
        participant_(domain),
        loop_(participant_),
        announcer_(participant_, options_.id, "admittance_control"),
        context_{options_, null_logger(), participant_, loop_, announcer_, Config::parse("{}", "bench")},
        node_(context_),
        commands_(participant_, protocol::admittance::kCommand) {
    loop_.every(kPeriod, [this] {
      const auto now = Clock::now();
      // The first wake-up of a slice is the one due while the bare loop had the thread: not counted.
      if (recording_ && !resumed_) lateness_us.push_back(std::chrono::duration<double, std::micro>(now - deadline_).count());
      deadline_ = std::max(deadline_ + kPeriod, now);  // as EventLoop re-schedules after a stall
      resumed_ = false;
    });
    deadline_ = Clock::now() + kPeriod;  // the probe's first deadline, as EventLoop::every sets it
    // ROBOT mode, so that the robot step does its full work (and publishes twists).
    rigger_admittance_AdmittanceCommand c{};
    c.header.stamp = dds::wire_now();
    c.seq = 1;
    c.mode = rigger_admittance_ADMITTANCE_ROBOT;
    c.reference = rigger_admittance_REFERENCE_NONE;
    commands_.write(c);
    loop_.run_until([] { return false; }, std::chrono::seconds(1));  // warm-up
  }

  void measure(std::chrono::nanoseconds slice) {
    recording_ = true;
    resumed_ = true;
    loop_.run_until([] { return false; }, slice);
    recording_ = false;
  }

  std::vector<double> lateness_us;

 private:
  service::ServiceOptions options_;
  dds::Participant participant_;
  dds::EventLoop loop_;
  service::ServiceAnnouncer announcer_;
  service::ServiceContext context_;
  AdmittanceNode node_;
  dds::Writer<rigger_admittance_AdmittanceCommand> commands_;
  Clock::time_point deadline_{};
  bool recording_ = false;
  bool resumed_ = false;
};

void measure_bare_loop(std::chrono::nanoseconds duration, std::vector<double>& lateness_us) {
  timespec now{};
  clock_gettime(CLOCK_MONOTONIC, &now);
  std::chrono::nanoseconds next = std::chrono::seconds(now.tv_sec) + std::chrono::nanoseconds(now.tv_nsec);
  const auto end = next + duration;
  while (next < end) {
    next += kPeriod;
    const timespec ts = to_timespec(next);
    clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &ts, nullptr);
    clock_gettime(CLOCK_MONOTONIC, &now);
    const auto woke = std::chrono::seconds(now.tv_sec) + std::chrono::nanoseconds(now.tv_nsec);
    lateness_us.push_back(std::chrono::duration<double, std::micro>(woke - next).count());
  }
}

}  // namespace
}  // namespace rigger::control

int main(int argc, char** argv) {
  using namespace rigger::control;
  int seconds = 10;
  for (int i = 1; i + 1 < argc; ++i)
    if (std::strcmp(argv[i], "--seconds") == 0) seconds = std::max(1, std::atoi(argv[i + 1]));
  rigger::testing::DomainLease lease;
  std::atomic<bool> stop{false};
  std::thread feeder([&] { feed(lease.id(), stop); });
  std::vector<double> bare;
  {
    NodeLoop node(lease.id());
    for (int slice = 0; slice < seconds; ++slice) {
      node.measure(std::chrono::seconds(1));
      measure_bare_loop(std::chrono::seconds(1), bare);
    }
    stop = true;
    feeder.join();
    std::printf("wake-up lateness of a 2 ms loop, %d s each in 1 s turns, 1 kHz wrench stream running:\n",
                seconds);
    print("admittance node's EventLoop (probe timer)", node.lateness_us);
    print("bare clock_nanosleep(TIMER_ABSTIME) loop", bare);
    std::printf("p99.9 ratio node/bare: %.2f (target <= 1.2)\n",
                quantile(node.lateness_us, 0.999) / std::max(1e-9, quantile(bare, 0.999)));
    rigger::performance::Report report("rigger_admittance_loop_bench",
                                       "Wake-up lateness of the admittance node's 2 ms control loop (probe timer), " +
                                           std::to_string(seconds) +
                                           " s in 1 s turns with a 1 kHz wrench stream, next to a bare "
                                           "clock_nanosleep(TIMER_ABSTIME) loop in the other turns");
    const std::pair<const char*, double> levels[] = {{"p50", 0.5}, {"p99", 0.99}, {"p99.9", 0.999}, {"max", 1.0}};
    for (const auto& [level, q] : levels)
      report.add({std::string("node loop lateness ") + level, quantile(node.lateness_us, q), "us",
                  std::string("bare loop lateness ") + level, quantile(bare, q)});
    return rigger::performance::save_for_main(report);
  }
}
