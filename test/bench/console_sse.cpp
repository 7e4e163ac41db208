// Console event latency: a node status written on rigger/task/node_status here, read by a
// console process, numbered and sent as a Server-Sent Event to an HTTP client here: the time from the
// write to the event's arrival. Printed next to the DDS one-way floor of the same run (half of
// ddsperf's ping/pong round trip). The console holds a task of 10,000 nodes meanwhile; the trials run
// with 1, 10 and 50 browsers (SSE streams) connected, each timed at every stream.
//
//   build/bench/bench_console_sse [--trials 1000] [--rate 200] [--task-nodes 10000]
#include <atomic>
#include <cstdio>
#include <memory>
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
  const int background_nodes = rigger::bench::int_option(argc, argv, "--task-nodes", 10000);

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

  // The task the browsers watch: 10,000 nodes the console holds before the trials.
  const auto node_status = [](const std::string& task, const std::string& id) {
    rigger_task_NodeStatus s{};
    const std::string parent = "", type = "Skill";
    s.task_id = dds::wire_string(task);
    s.node_id = dds::wire_string(id);
    s.parent_id = dds::wire_string(parent);
    s.node_type = dds::wire_string(type);
    s.name = dds::wire_string(id);
    s.state = rigger_task_NODE_RUNNING;
    s.stamp = dds::wire_now();
    return s;
  };
  for (int i = 0; i < background_nodes; ++i) {
    nodes.write(node_status("big", "big-" + std::to_string(i)));
    if (i % 500 == 499) cell.wait_until([] { return false; }, 5ms);  // no burst the reader's history would drop
  }

  // Each run: `clients` SSE streams, the trials' node statuses written at rate_hz, each one's arrival at
  // every stream timed; latency_us has one figure per trial and client.
  const auto run = [&](int clients, const std::string& prefix) {
    std::vector<Clock::time_point> sent(static_cast<std::size_t>(trials));
    std::vector<std::vector<Clock::time_point>> got(static_cast<std::size_t>(clients),
                                                    std::vector<Clock::time_point>(static_cast<std::size_t>(trials)));
    std::atomic<int> received{0}, streaming{0};
    std::vector<std::unique_ptr<httplib::Client>> http;
    std::vector<std::thread> readers;
    const std::string marker = "\"node_id\":\"" + prefix;
    for (int c = 0; c < clients; ++c) {
      http.push_back(std::make_unique<httplib::Client>("127.0.0.1", port));
      http.back()->set_read_timeout(60, 0);
      readers.emplace_back([&, c] {
        std::string buffer;
        bool counted = false;
        http[static_cast<std::size_t>(c)]->Get(("/api/events?token=" + users[0].token).c_str(), [&](const char* data, std::size_t n) {
          if (!counted) ++streaming;
          counted = true;
          rigger::bench::take_sse_events(buffer, data, n, [&](std::string_view event) {
            const auto at = event.find(marker);
            if (at == std::string_view::npos) return;
            const int i = std::atoi(event.data() + at + marker.size());
            if (i >= 0 && i < trials) got[static_cast<std::size_t>(c)][static_cast<std::size_t>(i)] = Clock::now();
            ++received;
          });
          return received < trials * clients;
        });
      });
    }
    cell.wait_until([&] { return streaming.load() == clients; }, 5s);  // a head start: the first keep-alive comes later
    for (int i = 0; i < trials; ++i) {
      sent[static_cast<std::size_t>(i)] = Clock::now();
      nodes.write(node_status("bench", prefix + std::to_string(i)));
      cell.wait_until([] { return false; }, std::chrono::milliseconds(1000 / rate_hz));
    }
    cell.wait_until([&] { return received >= trials * clients; }, 20s);
    for (auto& h : http) h->stop();
    for (auto& r : readers) r.join();
    std::vector<double> latency_us;
    for (const auto& g : got)
      for (int i = 0; i < trials; ++i)
        if (g[static_cast<std::size_t>(i)] > sent[static_cast<std::size_t>(i)])
          latency_us.push_back(
              std::chrono::duration<double, std::micro>(g[static_cast<std::size_t>(i)] - sent[static_cast<std::size_t>(i)]).count());
    return latency_us;
  };
  const std::vector<int> client_counts = {1, 10, 50};
  std::vector<std::vector<double>> latencies;
  for (const int clients : client_counts) latencies.push_back(run(clients, "bench" + std::to_string(clients) + "-"));
  const std::vector<double>& latency_us = latencies.front();
  cell.stop_all();

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
  std::printf("\nWith %d nodes of another task held and 1, 10 and 50 browsers (SSE streams) connected:\n%8s %10s %10s %10s %8s\n",
              background_nodes, "streams", "p50 us", "p90 us", "p99 us", "events");
  for (std::size_t k = 0; k < client_counts.size(); ++k)
    std::printf("%8d %10.1f %10.1f %10.1f %8zu\n", client_counts[k], percentile(latencies[k], 0.5),
                percentile(latencies[k], 0.9), percentile(latencies[k], 0.99), latencies[k].size());
  std::printf("p99, 1 -> %d streams: %s\n", client_counts.back(),
              rigger::bench::growth_verdict(percentile(latencies.front(), 0.99), percentile(latencies.back(), 0.99),
                                            client_counts.back())
                  .c_str());
  for (std::size_t k = 0; k < client_counts.size(); ++k)
    if (static_cast<int>(latencies[k].size()) != trials * client_counts[k]) return 1;

  rigger::performance::Report report(
      "bench_console_sse", "Node status written -> console -> SSE event received, " + std::to_string(rate_hz) +
                               " Hz, " + std::to_string(trials) +
                               " trials, loopback, next to the DDS one-way floor (ddsperf ping/pong 512 B / 2)");
  // Without ddsperf's figures (printed as unavailable above), the figures go without their reference.
  rigger::bench::add_quantiles(report, "node status -> SSE event", rigger::bench::quantiles(latency_us), "us",
                               ref.count > 0 ? "ddsperf waitset one way" : "", rigger::bench::one_way(ref));
  for (std::size_t k = 1; k < client_counts.size(); ++k)
    rigger::bench::add_quantiles(report, "node status -> SSE event, " + std::to_string(client_counts[k]) + " streams",
                                 rigger::bench::quantiles(latencies[k]), "us", "node status -> SSE event",
                                 rigger::bench::quantiles(latency_us));
  return rigger::performance::save_for_main(report);
}
