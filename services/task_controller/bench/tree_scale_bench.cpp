// How the controller's reaction and memory grow with the tree: the live reaction (live_reaction.*: the
// controller and two scripted executors as real processes on a private domain, one host) of pattern A
// (a monitor's FAILURE -> the sibling skill's SHUTDOWN received) and B (a leaf's SUCCESS -> the next
// leaf's START received), in recipes of about 10, 1k, 10k and 100k nodes: the pattern's tree in a
// Fallback with a Sequence of leaves that never start. Run on demand, not a test. Prints per size p50
// and p99 of A and B, the controller's peak and final resident memory, and the figures of the relay
// floor (relay_floor.cpp: the same hop and nothing else) measured in the same run at the smallest size
// as the reference; then whether each curve is flat (largest / smallest <= 1.2), linear or worse.
//
//   build/bench/task_controller_tree_scale_bench [--trials 300] [--period-ms 10] [--sizes 10,1000,10000,100000]
//
// Exit 0 when every run paired all its trials and every task succeeded; the verdicts are figures.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <sstream>
#include <string>
#include <vector>

#include "bench_util.hpp"
#include "live_reaction.hpp"

namespace {

using rigger::bench::measure_reaction;
using rigger::bench::Pattern;
using rigger::bench::percentile;
using rigger::bench::Reaction;

struct Point {
  int nodes_asked = 0;
  Reaction a, b;
};

std::string verdict(const std::vector<double>& figures, const std::vector<int>& sizes) {
  return rigger::bench::growth_verdict(figures.front(), figures.back(), static_cast<double>(sizes.back()) / sizes.front());
}

}  // namespace

int main(int argc, char** argv) {
  int trials = 300, period_ms = 10;
  std::vector<int> sizes = {10, 1000, 10000, 100000};
  for (int i = 1; i + 1 < argc; i += 2) {
    if (!std::strcmp(argv[i], "--trials")) trials = std::max(20, std::atoi(argv[i + 1]));
    else if (!std::strcmp(argv[i], "--period-ms")) period_ms = std::max(1, std::atoi(argv[i + 1]));
    else if (!std::strcmp(argv[i], "--sizes")) {
      sizes.clear();
      std::stringstream list(argv[i + 1]);
      for (std::string item; std::getline(list, item, ',');) sizes.push_back(std::max(1, std::atoi(item.c_str())));
    } else {
      std::fprintf(stderr, "unknown option %s\n", argv[i]);
      return 2;
    }
  }
  if (sizes.empty()) return 2;
  std::sort(sizes.begin(), sizes.end());

  std::vector<Point> points;
  Reaction floor_a, floor_b;
  for (const int nodes : sizes) {
    Point p;
    p.nodes_asked = nodes;
    rigger::bench::ReactionSetup setup;
    setup.tree_nodes = nodes;
    setup.warmup_trials = 20;
    setup.relay = nodes == sizes.front();  // the floor, once, in the same run
    setup.cell_subfolder = "tree-" + std::to_string(nodes) + "-a";
    p.a = measure_reaction(Pattern::kMonitorFailure, "normal", trials, period_ms, setup);
    setup.cell_subfolder = "tree-" + std::to_string(nodes) + "-b";
    p.b = measure_reaction(Pattern::kSuccessNext, "normal", trials, period_ms, setup);
    if (!p.a.ok || !p.b.ok) {
      std::fprintf(stderr, "the run with %d nodes failed (A %s, B %s)\n", nodes, p.a.ok ? "ok" : "failed",
                   p.b.ok ? "ok" : "failed");
      return 1;
    }
    if (setup.relay) {
      floor_a = p.a;
      floor_b = p.b;
    }
    std::printf("%7d nodes: A p50 %7.1f p99 %7.1f us, B p50 %7.1f p99 %7.1f us, controller peak %6.1f MiB\n",
                p.a.tree_nodes, percentile(p.a.command_received_us, 0.5), percentile(p.a.command_received_us, 0.99),
                percentile(p.b.command_received_us, 0.5), percentile(p.b.command_received_us, 0.99),
                std::max(p.a.controller_peak_kib, p.b.controller_peak_kib) / 1024.0);
    std::fflush(stdout);
    points.push_back(std::move(p));
  }

  std::printf("\nReaction (event written -> command received by its executor, us) and controller memory by tree "
              "size;\n%d trials per pattern, %d ms period, journal normal; one host.\n\n",
              trials, period_ms);
  std::printf("%9s %9s %9s %9s %9s %11s %11s\n", "nodes", "A p50", "A p99", "B p50", "B p99", "peak MiB", "end MiB");
  std::printf("%9s %9.1f %9.1f %9.1f %9.1f %11s %11s\n", "relay", percentile(floor_a.relay.command_received_us, 0.5),
              percentile(floor_a.relay.command_received_us, 0.99), percentile(floor_b.relay.command_received_us, 0.5),
              percentile(floor_b.relay.command_received_us, 0.99), "-", "-");
  std::vector<double> a50, a99, b50, b99, peak;
  for (const Point& p : points) {
    a50.push_back(percentile(p.a.command_received_us, 0.5));
    a99.push_back(percentile(p.a.command_received_us, 0.99));
    b50.push_back(percentile(p.b.command_received_us, 0.5));
    b99.push_back(percentile(p.b.command_received_us, 0.99));
    peak.push_back(std::max(p.a.controller_peak_kib, p.b.controller_peak_kib) / 1024.0);
    std::printf("%9d %9.1f %9.1f %9.1f %9.1f %11.1f %11.1f\n", p.a.tree_nodes, a50.back(), a99.back(), b50.back(),
                b99.back(), peak.back(), std::max(p.a.controller_rss_kib, p.b.controller_rss_kib) / 1024.0);
  }
  std::vector<int> nodes;
  for (const Point& p : points) nodes.push_back(p.a.tree_nodes);
  std::printf("\nA p50 %s\nA p99 %s\nB p50 %s\nB p99 %s\npeak memory %s\n", verdict(a50, nodes).c_str(),
              verdict(a99, nodes).c_str(), verdict(b50, nodes).c_str(), verdict(b99, nodes).c_str(),
              verdict(peak, nodes).c_str());

  rigger::performance::Report report(
      "task_controller_tree_scale_bench",
      "Skill-event reaction and controller memory by tree size (the pattern's tree in a Fallback with leaves that "
      "never start), " + std::to_string(trials) + " trials per pattern, next to the relay floor of the same run");
  using rigger::bench::add_quantiles;
  using rigger::bench::quantiles;
  for (const Point& p : points) {
    const std::string n = std::to_string(p.a.tree_nodes) + " nodes";
    add_quantiles(report, "A SHUTDOWN received, " + n, quantiles(p.a.command_received_us), "us",
                  "A SHUTDOWN received, relay floor", quantiles(floor_a.relay.command_received_us));
    add_quantiles(report, "B START received, " + n, quantiles(p.b.command_received_us), "us",
                  "B START received, relay floor", quantiles(floor_b.relay.command_received_us));
    report.add({"controller peak memory, " + n,
                std::max(p.a.controller_peak_kib, p.b.controller_peak_kib) / 1024.0, "MiB", "", 0});
  }
  return rigger::performance::save_for_main(report);
}
