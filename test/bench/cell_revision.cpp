// Cell revisions: the world model's start-up on the demo cell (process start to READY, its STEP models'
// CAD rules derived) next to its start-up on a one-frame cell; and a revision's apply (request written to
// the CellRevision received, the demo cell's load moved each time) next to a world query round trip
// measured in the same run.
//
//   build/bench/bench_cell_revision [--starts 5] [--applies 30] [--queries 500]
#include <signal.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "bench_util.hpp"
#include "rigger/dds/pubsub.hpp"
#include "rigger/protocol/world.hpp"
#include "rigger/testing/cell.hpp"
#include "rigger/world_client/world_client.hpp"
#include "rigger/world_protocol/cell_protocol.hpp"

namespace {

using namespace std::chrono_literals;
using Clock = std::chrono::steady_clock;
namespace fs = std::filesystem;
using json = nlohmann::json;

double ms_since(Clock::time_point t) {
  return std::chrono::duration<double, std::milli>(Clock::now() - t).count();
}

std::string read_text(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

// Start to READY of a world model on `cell_file`, `runs` times (each with a fresh database and history).
std::vector<double> start_ups(rigger::testing::Cell& cell, const std::string& cell_file, const std::string& tag,
                              int runs) {
  std::vector<double> ms;
  for (int i = 0; i < runs; ++i) {
    const std::string id = tag + std::to_string(i);
    const auto t0 = Clock::now();
    cell.start(id, "world_model",
               {"--id", id, "--log-level", "warn", "--cell", cell_file, "--db", cell.log_dir() + "/" + id + ".sqlite"});
    if (!cell.wait_ready({id}, 60s)) {
      std::fprintf(stderr, "world_model %s did not become ready\n%s", id.c_str(), cell.logs().c_str());
      return {};
    }
    ms.push_back(ms_since(t0));
    cell.stop(id, SIGINT, 20s);
  }
  return ms;
}

}  // namespace

int main(int argc, char** argv) {
  using rigger::bench::int_option;
  const int starts = int_option(argc, argv, "--starts", 5), applies = int_option(argc, argv, "--applies", 30),
            queries = int_option(argc, argv, "--queries", 500);
  rigger::testing::Cell cell;
  const fs::path folder = fs::path(cell.log_dir()) / "cell";
  fs::create_directories(folder);
  const fs::path shipped = fs::path(RIGGER_SOURCE_DIR) / "deploy/cell";
  fs::copy(shipped / "simulated_cell.json", folder / "cell.json");
  fs::copy(shipped / "models", folder / "models", fs::copy_options::recursive);
  const std::string minimal = cell.log_dir() + "/minimal.json";
  std::ofstream(minimal)
      << R"({"cell_version":1,"description":"one frame","entities":[{"id":"world","kind":"frame"}]})";

  const std::vector<double> demo_ms = start_ups(cell, (folder / "cell.json").string(), "demo", starts);
  const std::vector<double> minimal_ms = start_ups(cell, minimal, "min", starts);
  if (demo_ms.empty() || minimal_ms.empty()) return 1;

  cell.start("wm", "world_model",
             {"--id", "wm", "--log-level", "warn", "--cell", (folder / "cell.json").string(), "--db",
              cell.log_dir() + "/wm.sqlite"});
  if (!cell.wait_ready({"wm"}, 60s)) return 1;
  auto& loop = cell.loop();
  rigger::dds::Reader<rigger_world_CellRevision> revisions(cell.participant(), rigger::protocol::world::kCell);
  rigger::dds::Writer<rigger_world_CellRequest> requests(cell.participant(), rigger::protocol::world::kCellRequest);
  std::uint64_t latest = 0;
  loop.on_data(revisions, [&] {
    revisions.take([&](const rigger_world_CellRevision& r, const dds_sample_info_t&) { latest = r.cell_revision; });
  });
  rigger::world_client::WorldClient client(cell.participant(), loop, rigger::null_logger(), "bench");
  if (!cell.wait_until([&] { return latest == 1 && client.connected() && requests.matched_readers() > 0; }, 20s)) {
    std::fprintf(stderr, "world model not matched\n");
    return 1;
  }
  const json original = json::parse(read_text(folder / "cell.json"));
  std::vector<double> apply_ms;
  for (int i = 1; i <= applies; ++i) {
    json doc = original;
    doc["entities"][5]["pose"]["position_m"][0] = doc["entities"][5]["pose"]["position_m"][0].get<double>() + 0.001 * i;
    rigger::world_protocol::CellRequest q;
    q.client_id = "bench";
    q.request_id = static_cast<std::uint64_t>(i);
    q.op = rigger::world_protocol::CellOp::kApply;
    q.cell_json = doc.dump();
    q.who = "bench";
    rigger_world_CellRequest wire{};
    rigger::world_protocol::to_wire(q, wire);
    const auto t0 = Clock::now();
    requests.write(wire);
    const std::uint64_t expected = latest + 1;
    if (!cell.wait_until([&] { return latest == expected; }, 30s)) {
      std::fprintf(stderr, "revision %llu not received\n%s", static_cast<unsigned long long>(expected),
                   cell.logs().c_str());
      return 1;
    }
    apply_ms.push_back(ms_since(t0));
  }
  std::vector<double> query_ms;
  for (int i = 0; i < queries; ++i) {
    bool done = false;
    const auto t0 = Clock::now();
    client.pose("load", "robot", 2s, [&](const rigger::world_client::Reply&) { done = true; });
    cell.wait_until([&] { return done; }, 3s);
    query_ms.push_back(ms_since(t0));
  }
  cell.stop_all();

  using rigger::bench::quantiles;
  const auto demo = quantiles(demo_ms), small = quantiles(minimal_ms), apply = quantiles(apply_ms),
             query = quantiles(query_ms);
  std::printf(
      "World model start-up (process start to READY, %d runs) and cell revision apply (%d revisions of the "
      "demo cell, the load moved each time), loopback, domain %u\n",
      starts, applies, cell.domain_id());
  std::printf("%-52s %10s %10s %10s\n", "", "p50 ms", "p90 ms", "p99 ms");
  std::printf("%-52s %10.1f %10.1f %10.1f\n", "start-up, demo cell (4 STEP models, CAD rules)", demo.p50, demo.p90,
              demo.p99);
  std::printf("%-52s %10.1f %10.1f %10.1f\n", "start-up, one-frame cell", small.p50, small.p90, small.p99);
  std::printf("%-52s %10.1f %10.1f %10.1f\n", "revision apply -> CellRevision received", apply.p50, apply.p90,
              apply.p99);
  std::printf("%-52s %10.3f %10.3f %10.3f\n", "world query round trip (pose load in robot)", query.p50, query.p90,
              query.p99);

  rigger::performance::Report report(
      "bench_cell_revision",
      "World model start-up (process start to READY) on the demo cell next to a one-frame cell; a cell revision's "
      "apply (request to CellRevision received, demo cell, load moved) next to a world query round trip, loopback");
  rigger::bench::add_quantiles(report, "start-up demo cell", demo, "ms", "start-up one-frame cell", small);
  rigger::bench::add_quantiles(report, "revision apply", apply, "ms", "world query round trip", query);
  return rigger::performance::save_for_main(report);
}
