// World-model query round trip: a world_model process holding 1,000 entities answers pose
// queries (A in the frame of B, through the frame tree) from a WorldClient, one request outstanding at
// a time; printed next to ddsperf's ping/pong round trip measured in the same run. Then the load curve:
// 1 and 10 clients (as 10 skills asking at once), each asking again as soon as it has its answer, for
// --seconds each: queries per second and the round trip's p50/p99, and whether it stays flat.
//
//   build/bench/bench_world_query [--rate 1000] [--seconds 10] [--entities 1000]
#include <cstdio>
#include <cstdlib>
#include <algorithm>
#include <fstream>
#include <functional>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "bench_util.hpp"
#include "rigger/testing/cell.hpp"
#include "rigger/world_client/world_client.hpp"

namespace {

using namespace std::chrono_literals;
using Clock = std::chrono::steady_clock;

struct Options {
  int rate_hz = 1000;
  int seconds = 10;
  int entities = 1000;
};

Options parse(int argc, char** argv) {
  using rigger::bench::int_option;
  return {int_option(argc, argv, "--rate", 1000), int_option(argc, argv, "--seconds", 10),
          int_option(argc, argv, "--entities", 1000)};
}

// world + 20 hub frames + objects spread over the hubs: every query composes poses through world.
std::vector<std::string> write_cell(const std::string& path, int count) {
  constexpr int kHubs = 20;
  nlohmann::json entities = nlohmann::json::array({{{"id", "world"}, {"kind", "frame"}}});
  std::vector<std::string> objects;
  for (int h = 0; h < kHubs; ++h) {
    entities.push_back({{"id", "hub_" + std::to_string(h)}, {"kind", "frame"}, {"parent", "world"},
                        {"pose", {{"position_m", {h * 0.5, 0.0, 0.0}}, {"rpy_deg", {0, 0, h * 10.0}}}}});
  }
  for (int i = 0; static_cast<int>(entities.size()) < count; ++i) {
    objects.push_back("obj_" + std::to_string(i));
    entities.push_back({{"id", objects.back()}, {"kind", "object"}, {"parent", "hub_" + std::to_string(i % kHubs)},
                        {"localized", true},
                        {"pose", {{"position_m", {0.01 * i, 0.2, 0.3}}, {"rpy_deg", {0, 5.0, 0.1 * i}}}}});
  }
  std::ofstream(path) << nlohmann::json{{"cell_version", 1}, {"description", "benchmark cell"}, {"entities", entities}};
  return objects;
}

}  // namespace

int main(int argc, char** argv) {
  const Options opt = parse(argc, argv);
  rigger::testing::Cell cell;
  const std::string cell_path = cell.log_dir() + "/bench_cell.json";
  const auto objects = write_cell(cell_path, opt.entities);
  cell.start("wm", "world_model",
             {"--id", "wm", "--log-level", "warn", "--cell", cell_path, "--db", cell.log_dir() + "/bench.sqlite"});
  if (!cell.wait_ready({"wm"}, 20s)) {
    std::fprintf(stderr, "world_model did not become ready\n%s", cell.logs().c_str());
    return 1;
  }
  auto& loop = cell.loop();
  rigger::world_client::WorldClient client(cell.participant(), loop, rigger::null_logger(), "bench");
  if (!cell.wait_until([&] { return client.connected(); }, 5s)) {
    std::fprintf(stderr, "world model not matched\n");
    return 1;
  }

  std::mt19937 rng(4);
  std::uniform_int_distribution<std::size_t> pick(0, objects.size() - 1);
  std::vector<double> rtt_us;
  int failures = 0;
  bool outstanding = false;
  const auto warmup_end = Clock::now() + 1s;
  const auto end = warmup_end + std::chrono::seconds(opt.seconds);
  loop.every(std::chrono::nanoseconds(1'000'000'000 / opt.rate_hz), [&] {
    if (outstanding) return;  // one at a time: a round trip, not a throughput test
    outstanding = true;
    const auto sent = Clock::now();
    client.pose(objects[pick(rng)], objects[pick(rng)], 2s, [&, sent](const rigger::world_client::Reply& r) {
      outstanding = false;
      if (!r.ok) ++failures;
      if (sent >= warmup_end) rtt_us.push_back(std::chrono::duration<double, std::micro>(Clock::now() - sent).count());
    });
  });
  loop.run_until([&] { return Clock::now() >= end; }, end - Clock::now() + 3s);

  // The load curve: n clients in a closed loop (each asks again when answered).
  struct Load {
    int clients = 0;
    double qps = 0;
    std::vector<double> rtt_us;
  };
  std::vector<Load> loads;
  for (const int n : {1, 10}) {
    std::vector<std::unique_ptr<rigger::world_client::WorldClient>> clients;
    for (int i = 0; i < n; ++i)
      clients.push_back(std::make_unique<rigger::world_client::WorldClient>(
          cell.participant(), loop, rigger::null_logger(), "bench-load-" + std::to_string(n) + "-" + std::to_string(i)));
    if (!cell.wait_until([&] { return std::all_of(clients.begin(), clients.end(), [](auto& c) { return c->connected(); }); }, 10s)) {
      std::fprintf(stderr, "%d world clients not matched\n", n);
      return 1;
    }
    Load load;
    load.clients = n;
    const auto from = Clock::now() + 1s;  // a second of warm-up
    const auto until = from + std::chrono::seconds(opt.seconds);
    int answered = 0, in_flight = 0;
    std::function<void(rigger::world_client::WorldClient&)> ask = [&](rigger::world_client::WorldClient& c) {
      if (Clock::now() >= until) return;
      ++in_flight;
      const auto sent = Clock::now();
      c.pose(objects[pick(rng)], objects[pick(rng)], 2s, [&, sent](const rigger::world_client::Reply& r) {
        --in_flight;
        if (!r.ok) ++failures;
        if (sent >= from && Clock::now() <= until) {
          ++answered;
          load.rtt_us.push_back(std::chrono::duration<double, std::micro>(Clock::now() - sent).count());
        }
        ask(c);
      });
    };
    for (auto& c : clients) ask(*c);
    loop.run_until([&] { return Clock::now() >= until && in_flight == 0; }, until - Clock::now() + 5s);
    load.qps = answered / static_cast<double>(opt.seconds);
    loads.push_back(std::move(load));
  }
  cell.stop_all();

  using rigger::bench::percentile;
  const double r50 = percentile(rtt_us, 0.50), r90 = percentile(rtt_us, 0.90), r99 = percentile(rtt_us, 0.99);
  const auto ref = rigger::bench::run_ddsperf_pingpong(cell.domain_id(), opt.rate_hz, 128, opt.seconds, true);
  if (ref.count == 0) {
    std::fprintf(stderr, "could not parse ddsperf output:\n%s\n", ref.raw.c_str());
    return 1;
  }
  std::printf("World-model pose query round trip, %d entities, %d Hz offered, %d s, loopback, domain %u\n",
              opt.entities, opt.rate_hz, opt.seconds, cell.domain_id());
  std::printf("%-44s %10s %10s %10s %8s\n", "", "p50 us", "p90 us", "p99 us", "samples");
  std::printf("%-44s %10.1f %10.1f %10.1f %8zu\n", "WorldClient.pose -> world_model -> reply", r50, r90, r99,
              rtt_us.size());
  std::printf("%-44s %10.1f %10.1f %10.1f %8llu\n", "ddsperf ping/pong 128 B, waitset", ref.p50_us, ref.p90_us,
              ref.p99_us, static_cast<unsigned long long>(ref.count));
  std::printf("failed queries: %d; ratio p50 %.2f  p99 %.2f\n", failures, r50 / ref.p50_us, r99 / ref.p99_us);
  std::printf("\nClosed loop (each client asks again when answered), %d s each:\n%8s %12s %10s %10s\n", opt.seconds,
              "clients", "queries/s", "p50 us", "p99 us");
  for (const Load& l : loads)
    std::printf("%8d %12.0f %10.1f %10.1f\n", l.clients, l.qps, percentile(l.rtt_us, 0.5), percentile(l.rtt_us, 0.99));
  std::printf("p99, 1 -> %d clients: %s; queries/s %.2fx\n", loads.back().clients,
              rigger::bench::growth_verdict(percentile(loads.front().rtt_us, 0.99), percentile(loads.back().rtt_us, 0.99),
                                            loads.back().clients)
                  .c_str(),
              loads.back().qps / loads.front().qps);
  if (failures != 0) return 1;

  rigger::performance::Report report("bench_world_query",
                                     "World-model pose query round trip (WorldClient.pose, one outstanding), " +
                                         std::to_string(opt.entities) + " entities, " + std::to_string(opt.rate_hz) +
                                         " Hz offered for " + std::to_string(opt.seconds) +
                                         " s, loopback, next to ddsperf ping/pong 128 B (waitset)");
  rigger::bench::add_quantiles(report, "pose query round trip", {r50, r90, r99}, "us", "ddsperf waitset round trip",
                               rigger::bench::round_trip(ref));
  for (const Load& l : loads) {
    const std::string who = std::to_string(l.clients) + (l.clients == 1 ? " client" : " clients");
    rigger::bench::add_quantiles(report, "pose query round trip, closed loop, " + who,
                                 {percentile(l.rtt_us, 0.5), percentile(l.rtt_us, 0.9), percentile(l.rtt_us, 0.99)}, "us",
                                 "pose query round trip", {r50, r90, r99});
    report.add({"pose queries per second, closed loop, " + who, l.qps, "1/s", "", 0});
  }
  return rigger::performance::save_for_main(report);
}
