// Console event latency: a node status written on rigger/task/node_status here, read by a
// console process, numbered and sent as a Server-Sent Event to an HTTP client here: the time from the
// write to the event's arrival. Printed next to the DDS one-way floor of the same run (half of
// ddsperf's ping/pong round trip).
//
//   build/bench/bench_console_sse [--trials 1000] [--rate 200]
#include <atomic>
#include <cstdio>
#include <mutex>
#include <string_view>
#include <thread>
#include <vector>

#include "bench_util.hpp"
#include "console_bench.hpp"
#include "rigger/dds/conversions.hpp"
#include "rigger/dds/pubsub.hpp"
#include "rigger/protocol/task.hpp"
#include "rigger/testing/cell.hpp"

// Last: its system headers define macros that break Eigen's (pulled in above).
#include <httplib.h>

int main(int argc, char** argv) {
  using namespace std::chrono_literals;
  using Clock = std::chrono::steady_clock;
  namespace dds = rigger::dds;
  const int trials = rigger::bench::int_option(argc, argv, "--trials", 1000);
  const int rate_hz = rigger::bench::int_option(argc, argv, "--rate", 200);

  rigger::testing::Cell cell;
  const auto console = rigger::bench::start_console(cell, {{"bench", rigger::console::Role::kViewer}});
  const auto& users = console.users;
  const std::uint16_t port = console.port;
  if (!cell.wait_ready({"console"}, 20s)) {
    std::fprintf(stderr, "the console did not become ready\n%s", cell.logs().c_str());
    return 1;
  }
  dds::Writer<rigger_task_NodeStatus> nodes(cell.participant(), rigger::protocol::task::kNodeStatus, dds::qos::state_changes());
  if (!nodes.wait_for_readers(1, 10s)) {
    std::fprintf(stderr, "the console's node-status reader did not match\n");
    return 1;
  }

  std::vector<Clock::time_point> sent(static_cast<std::size_t>(trials)), got(static_cast<std::size_t>(trials));
  std::atomic<int> received{0};
  std::atomic<bool> streaming{false};
  httplib::Client client("127.0.0.1", port);
  client.set_read_timeout(30, 0);
  std::thread reader([&] {
    std::string buffer;
    client.Get(("/api/events?token=" + users[0].token).c_str(), [&](const char* data, std::size_t n) {
      streaming = true;
      rigger::bench::take_sse_events(buffer, data, n, [&](std::string_view event) {
        const auto at = event.find("\"node_id\":\"bench-");
        if (at == std::string_view::npos) return;
        const int i = std::atoi(event.data() + at + 17);
        if (i >= 0 && i < trials) got[static_cast<std::size_t>(i)] = Clock::now();
        ++received;
      });
      return received < trials;
    });
  });
  cell.wait_until([&] { return streaming.load(); }, 1s);  // the first keep-alive comes later: just a head start
  for (int i = 0; i < trials; ++i) {
    const std::string id = "bench-" + std::to_string(i), task = "bench", parent = "", type = "Skill";
    rigger_task_NodeStatus s{};
    s.task_id = dds::wire_string(task);
    s.node_id = dds::wire_string(id);
    s.parent_id = dds::wire_string(parent);
    s.node_type = dds::wire_string(type);
    s.name = dds::wire_string(id);
    s.state = rigger_task_NODE_RUNNING;
    s.stamp = dds::wire_now();
    sent[static_cast<std::size_t>(i)] = Clock::now();
    nodes.write(s);
    cell.wait_until([] { return false; }, std::chrono::milliseconds(1000 / rate_hz));
  }
  cell.wait_until([&] { return received >= trials; }, 10s);
  client.stop();
  reader.join();
  cell.stop_all();

  std::vector<double> latency_us;
  for (int i = 0; i < trials; ++i)
    if (got[static_cast<std::size_t>(i)] > sent[static_cast<std::size_t>(i)])
      latency_us.push_back(std::chrono::duration<double, std::micro>(got[static_cast<std::size_t>(i)] - sent[static_cast<std::size_t>(i)]).count());
  const auto ref = rigger::bench::run_ddsperf_pingpong(cell.domain_id(), rate_hz, 512, 10, true);
  using rigger::bench::percentile;
  std::printf("node status written -> console -> SSE event received, %d Hz, %zu of %d, loopback\n", rate_hz,
              latency_us.size(), trials);
  std::printf("%-48s %10s %10s %10s %8s\n", "", "p50 us", "p90 us", "p99 us", "samples");
  std::printf("%-48s %10.1f %10.1f %10.1f %8zu\n", "node status -> SSE event (DDS hop + HTTP)", percentile(latency_us, 0.5),
              percentile(latency_us, 0.9), percentile(latency_us, 0.99), latency_us.size());
  if (ref.count > 0)
    std::printf("%-48s %10.1f %10.1f %10.1f\n", "DDS one-way floor (ddsperf ping/pong / 2, 512 B)", ref.p50_us / 2,
                ref.p90_us / 2, ref.p99_us / 2);
  else
    std::printf("ddsperf reference unavailable:\n%s\n", ref.raw.c_str());
  if (static_cast<int>(latency_us.size()) != trials) return 1;

  rigger::performance::Report report(
      "bench_console_sse", "Node status written -> console -> SSE event received, " + std::to_string(rate_hz) +
                               " Hz, " + std::to_string(trials) +
                               " trials, loopback, next to the DDS one-way floor (ddsperf ping/pong 512 B / 2)");
  // Without ddsperf's figures (printed as unavailable above), the figures go without their reference.
  rigger::bench::add_quantiles(report, "node status -> SSE event", rigger::bench::quantiles(latency_us), "us",
                               ref.count > 0 ? "ddsperf waitset one way" : "", rigger::bench::one_way(ref));
  return rigger::performance::save_for_main(report);
}
