// Cell revisions: the world model's start-up on the demo cell (process start to READY, its STEP models'
// CAD rules derived) next to its start-up on a one-frame cell; a revision's apply (request written to
// the CellRevision received, the demo cell's load moved each time) next to a world query round trip
// measured in the same run; and the same apply until every reader of the cell (cell_sim, vision_tracker,
// admittance_control, cad) says in its service state that it runs on the new revision; and a revision
// that adds a part whose STEP model only the request carries (a drilled plate written by OpenCascade,
// different bytes each time) until every reader has the model and runs on the revision.
//
//   build/bench/bench_cell_revision [--starts 5] [--applies 30] [--queries 500] [--uploads 5]
#include <signal.h>

#include <cstdio>
#include <filesystem>
#include <functional>
#include <fstream>
#include <iterator>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "bench_util.hpp"
#include "cell_sim_test_support.hpp"
#include "rigger/base/sha256.hpp"
#include "rigger/cad/model.hpp"
#include "rigger/cad/parts.hpp"
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

// deploy/config/<name>.json with its cell file replaced by `cell_file`, written next to the logs.
std::string reader_config(rigger::testing::Cell& cell, const std::string& name, const fs::path& cell_file) {
  json c = json::parse(read_text(fs::path(RIGGER_SOURCE_DIR) / "deploy/config" / (name + ".json")));
  for (const char* key : {"cell_file", "cell_config"}) {
    if (c.contains(key)) c[key] = cell_file.string();
  }
  const std::string path = cell.log_dir() + "/" + name + ".json";
  std::ofstream(path) << c.dump(2);
  return path;
}

}  // namespace

int main(int argc, char** argv) {
  using rigger::bench::int_option;
  const int starts = int_option(argc, argv, "--starts", 5), applies = int_option(argc, argv, "--applies", 30),
            queries = int_option(argc, argv, "--queries", 500), uploads = int_option(argc, argv, "--uploads", 5);
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
  // Revisions that move object `id` by i mm along x in the i-th; `done(revision)` says when one is through.
  // The milliseconds from each request written to done.
  std::uint64_t request_id = 0;
  // When set, the i-th request of apply_all is changed by it (a part and its model added).
  std::function<void(int, json&, rigger::world_protocol::CellRequest&)> upload;
  const auto apply_all = [&](const std::string& id, int count, const std::function<bool(std::uint64_t)>& done) {
    std::vector<double> ms;
    for (int i = 1; i <= count; ++i) {
      json doc = original;
      for (json& entity : doc["entities"]) {
        if (entity["id"] != id) continue;
        json& x = entity["pose"]["position_m"][0];
        x = x.get<double>() + 0.001 * i;
      }
      rigger::world_protocol::CellRequest q;
      q.client_id = "bench";
      q.request_id = ++request_id;
      q.op = rigger::world_protocol::CellOp::kApply;
      q.cell_json = doc.dump();
      q.who = "bench";
      if (upload) upload(i, doc, q);
      rigger_world_CellRequest wire{};
      std::vector<rigger_world_CellModel> models;
      rigger::world_protocol::to_wire(q, wire, models);
      const auto t0 = Clock::now();
      requests.write(wire);
      const std::uint64_t expected = latest + 1;
      if (!cell.wait_until([&] { return latest == expected && done(expected); }, 30s)) {
        std::fprintf(stderr, "revision %llu not through\n%s", static_cast<unsigned long long>(expected),
                     cell.logs().c_str());
        return std::vector<double>{};
      }
      ms.push_back(ms_since(t0));
    }
    return ms;
  };
  const std::vector<double> apply_ms = apply_all("load", applies, [](std::uint64_t) { return true; });
  if (apply_ms.empty()) return 1;
  std::vector<double> query_ms;
  for (int i = 0; i < queries; ++i) {
    bool done = false;
    const auto t0 = Clock::now();
    client.pose("load", "robot", 2s, [&](const rigger::world_client::Reply&) { done = true; });
    cell.wait_until([&] { return done; }, 3s);
    query_ms.push_back(ms_since(t0));
  }
  // The load back where the file has it (it hangs on the rope: cell_sim refuses to move it), then every
  // reader of the cell on the same file: from the request until each says it runs on the revision.
  if (apply_all("", 1, [](std::uint64_t) { return true; }).empty()) return 1;
  const std::vector<std::string> readers = {"cell_sim", "vision_tracker", "admittance_control", "cad"};
  const fs::path cell_file = folder / "cell.json";
  cell.start("cell_sim", "cell_sim",
             {"--config", reader_config(cell, "cell_sim", cell_file), "--plc-port", "0"});
  for (const char* name : {"vision_tracker", "admittance_control", "cad"})
    cell.start(name, name, {"--config", reader_config(cell, name, cell_file)});
  const auto all_on = [&](std::uint64_t revision) {
    const std::string on = "cell revision " + std::to_string(revision);
    for (const std::string& id : readers) {
      const auto it = cell.directory().services().find(id);
      if (it == cell.directory().services().end() || it->second.detail != on) return false;
    }
    return true;
  };
  if (!cell.wait_ready(readers, 60s) || !cell.wait_until([&] { return all_on(latest); }, 30s)) {
    std::fprintf(stderr, "the readers did not start on revision %llu\n%s", static_cast<unsigned long long>(latest),
                 cell.logs().c_str());
    return 1;
  }
  const std::vector<double> everyone_ms = apply_all("part", applies, all_on);  // a loose part: the load hangs on the rope
  if (everyone_ms.empty()) return 1;
  // A 0.6 x 0.4 m plate with 200 drilled holes: a STEP file of the size a real part's has.
  std::vector<rigger::cad::parts::DrilledHole> holes;
  for (int i = 0; i < 200; ++i)
    holes.push_back({Eigen::Vector3d(-0.28 + 0.0285 * (i % 20), -0.18 + 0.04 * (i / 20), 0.01), Eigen::Vector3d::UnitZ(),
                     0.008, 0.01, true});
  const fs::path plate = fs::path(cell.log_dir()) / "plate.step";
  rigger::cad::write_step(
      rigger::cad::parts::drilled_box(Eigen::Vector3d(-0.3, -0.2, 0), Eigen::Vector3d(0.3, 0.2, 0.01), holes), "plate", plate);
  const std::string plate_bytes = read_text(plate);
  upload = [&](int i, json& doc, rigger::world_protocol::CellRequest& q) {
    // Other bytes each time (a STEP comment), so that every reader receives the model anew.
    std::string bytes = plate_bytes;
    bytes.insert(bytes.find("HEADER;"), "/* upload " + std::to_string(i) + " */\n");
    const std::string sha = rigger::sha256_hex(bytes);
    doc["entities"].push_back({{"id", "upload"},
                               {"kind", "object"},
                               {"parent", "world"},
                               {"pose", {{"position_m", {6.0, -2.0, 0.0}}, {"rpy_deg", {0, 0, 0}}}},
                               {"model", {{"frame", "the plate's bottom face"}, {"static", true},
                                          {"step", "imported/upload.step"}, {"sha256", sha}}}});
    q.cell_json = doc.dump();
    q.models = {{sha, "imported/upload.step", std::move(bytes)}};
  };
  // Per reader: when it first said it runs on the revision (the predicate is polled on every wake-up).
  std::map<std::string, std::vector<double>> reader_ms;
  std::map<std::string, bool> reader_on;
  Clock::time_point upload_start = Clock::now();
  std::uint64_t upload_revision = 0;
  const auto each_on = [&](std::uint64_t revision) {
    if (revision != upload_revision) {
      upload_revision = revision;
      upload_start = Clock::now();  // not the write, but within a loop wake-up of it
      reader_on.clear();
    }
    const std::string on = "cell revision " + std::to_string(revision);
    for (const std::string& id : readers) {
      const auto it = cell.directory().services().find(id);
      if (reader_on[id] || it == cell.directory().services().end() || it->second.detail != on) continue;
      reader_on[id] = true;
      reader_ms[id].push_back(ms_since(upload_start));
    }
    return all_on(revision);
  };
  const std::vector<double> upload_ms = apply_all("", uploads, each_on);
  if (upload_ms.empty()) return 1;
  cell.stop_all();

  using rigger::bench::quantiles;
  const auto demo = quantiles(demo_ms), small = quantiles(minimal_ms), apply = quantiles(apply_ms),
             query = quantiles(query_ms), everyone = quantiles(everyone_ms), uploaded = quantiles(upload_ms);
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
  std::printf("%-52s %10.1f %10.1f %10.1f\n", "revision apply -> every reader on it (4 services)", everyone.p50,
              everyone.p90, everyone.p99);
  std::printf("%-52s %10.3f %10.3f %10.3f\n", "world query round trip (pose load in robot)", query.p50, query.p90,
              query.p99);
  std::printf("%-52s %10.1f %10.1f %10.1f\n", "revision + its STEP model -> every reader on it", uploaded.p50,
              uploaded.p90, uploaded.p99);
  std::printf("  (a part added with its model, %zu KiB, %d revisions, different bytes each); per reader:\n",
              plate_bytes.size() / 1024, uploads);
  for (const auto& [id, ms] : reader_ms) {
    const auto q = quantiles(ms);
    std::printf("  %-50s %10.1f %10.1f %10.1f\n", id.c_str(), q.p50, q.p90, q.p99);
  }

  rigger::performance::Report report(
      "bench_cell_revision",
      "World model start-up (process start to READY) on the demo cell next to a one-frame cell; a cell revision's "
      "apply (request to CellRevision received, demo cell, load moved) next to a world query round trip, and to every reader of the cell on the new revision, loopback");
  rigger::bench::add_quantiles(report, "start-up demo cell", demo, "ms", "start-up one-frame cell", small);
  rigger::bench::add_quantiles(report, "revision apply", apply, "ms", "world query round trip", query);
  rigger::bench::add_quantiles(report, "revision apply to every reader (cell_sim, tracker, admittance, cad)", everyone,
                               "ms", "revision apply to the world model's CellRevision", apply);
  rigger::bench::add_quantiles(report,
                               "revision adding a part with its " + std::to_string(plate_bytes.size() / 1024) +
                                   " KiB STEP model to every reader",
                               uploaded, "ms", "revision moving a part to every reader", everyone);
  return rigger::performance::save_for_main(report);
}
