#include "run_archive.hpp"

#include <algorithm>
#include <cstdlib>
#include <regex>
#include <sstream>
#include <stdexcept>
#include <vector>

#include "cell_feed.hpp"

namespace rigger::console {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

bool active(const std::string& state) { return state == "ACCEPTED" || state == "RUNNING" || state == "PAUSED"; }
bool final_state(const std::string& state) {
  return state == "SUCCEEDED" || state == "FAILED" || state == "CANCELED" || state == "REJECTED";
}
bool valid_task_id(const std::string& id) {
  static const std::regex kTaskId("[A-Za-z0-9][A-Za-z0-9_.-]{0,127}");
  return std::regex_match(id, kTaskId);
}

// A time of run.json, 0 while it is null (a run not ended, no row yet).
double time_of(const json& meta, const char* key) {
  const auto it = meta.find(key);
  return it != meta.end() && it->is_number() ? it->get<double>() : 0.0;
}

std::size_t count_lines(const fs::path& path, std::size_t at_most) {
  std::ifstream in(path);
  std::size_t n = 0;
  for (std::string line; n < at_most && std::getline(in, line);) n += !line.empty();
  return n;
}

}  // namespace

double plot_row_time(const std::string& row) {
  if (row.rfind("{\"t\":", 0) == 0) return std::strtod(row.c_str() + 5, nullptr);
  const json parsed = json::parse(row, nullptr, false);
  return parsed.is_object() && parsed.contains("t") && parsed["t"].is_number() ? parsed["t"].get<double>() : 0.0;
}

RunArchive::RunArchive(fs::path folder, Limits limits) : folder_(std::move(folder)), limits_(limits) {
  std::error_code ec;
  fs::create_directories(folder_, ec);
  if (ec) throw std::runtime_error(folder_.string() + ": cannot create the run archive: " + ec.message());
  for (const auto& entry : fs::directory_iterator(folder_, ec)) {
    const fs::path meta_path = entry.path() / "run.json";
    std::ifstream in(meta_path);
    if (!in) continue;
    json meta = json::parse(in, nullptr, false);
    if (meta.is_discarded() || !meta.is_object() || !meta.contains("task_id") ||
        meta["task_id"] != entry.path().filename().string() || !meta.contains("state") || !meta["state"].is_string() ||
        !meta.contains("rows") || !meta["rows"].is_number_unsigned())
      continue;  // not a run this archive wrote: left alone
    Run& run = runs_[meta["task_id"]];
    run.meta = std::move(meta);
    if (active(run.meta["state"].get<std::string>())) {
      // The console stopped during this run: go on appending to it.
      run.meta["rows"] = count_lines(entry.path() / "plots.jsonl", limits_.max_rows);
      run.rows.open(entry.path() / "plots.jsonl", std::ios::app);
      run.meta["cell_rows"] = count_lines(entry.path() / "cell.jsonl", limits_.max_rows);
      run.cell.open(entry.path() / "cell.jsonl", std::ios::app);
    }
  }
  if (ec) throw std::runtime_error(folder_.string() + ": cannot read the run archive: " + ec.message());
}

RunArchive::~RunArchive() {
  std::lock_guard lock(mutex_);
  for (auto& [id, run] : runs_)
    if (run.rows.is_open()) write_meta(run);
}

void RunArchive::on_task(const std::string& task_id, const std::string& state, double stamp_s) {
  if (!valid_task_id(task_id)) return;
  std::lock_guard lock(mutex_);
  const auto it = runs_.find(task_id);
  const bool open = it != runs_.end() && it->second.rows.is_open();
  if (active(state) && !open) {
    // A new run, unless this is the final state's run seen again (a late sample of an old run).
    if (it == runs_.end() || stamp_s > time_of(it->second.meta, "ended")) begin(task_id, state, stamp_s);
  } else if (open && final_state(state)) {
    finish(it->second, state, stamp_s);
  } else if (open) {
    it->second.meta["state"] = state;
  }
}

void RunArchive::on_row(const std::string& row_json) {
  std::lock_guard lock(mutex_);
  const double t = plot_row_time(row_json);
  for (auto& [id, run] : runs_) {
    if (!run.rows.is_open()) continue;
    append(run, run.rows, "rows", row_json);
    json& meta = run.meta;
    if (meta["first"].is_null()) meta["first"] = t;
    meta["last"] = t;
  }
}

void RunArchive::on_cell(const json& change) {
  std::lock_guard lock(mutex_);
  merge_cell(cell_, change);
  const std::string line = change.dump(-1, ' ', false, json::error_handler_t::replace);
  for (auto& [id, run] : runs_)
    if (run.cell.is_open()) append(run, run.cell, "cell_rows", line);
}

void RunArchive::append(Run& run, std::ofstream& out, const char* count_key, const std::string& line) {
  json& meta = run.meta;
  const std::size_t n = meta.value(count_key, std::size_t{0});
  if (n >= limits_.max_rows) {
    meta["truncated"] = true;
    return;
  }
  out << line << '\n';
  out.flush();
  meta[count_key] = n + 1;
}

json RunArchive::runs() const {
  std::lock_guard lock(mutex_);
  std::vector<json> list;
  for (const auto& [id, run] : runs_) list.push_back(run.meta);
  std::sort(list.begin(), list.end(),
            [](const json& a, const json& b) { return time_of(a, "started") > time_of(b, "started"); });
  return list;
}

std::optional<std::string> RunArchive::rows(const std::string& task_id) const {
  return read_rows(task_id, "plots.jsonl", "rows");
}

std::optional<std::string> RunArchive::cell_rows(const std::string& task_id) const {
  return read_rows(task_id, "cell.jsonl", "cell_rows");
}

std::optional<std::string> RunArchive::read_rows(const std::string& task_id, const char* file,
                                                 const char* count_key) const {
  std::unique_lock lock(mutex_);
  if (!valid_task_id(task_id) || runs_.count(task_id) == 0) return std::nullopt;
  const std::size_t kept = runs_.at(task_id).meta.value(count_key, std::size_t{0});
  lock.unlock();
  std::ifstream in(folder_ / task_id / file);
  std::string out = "[";
  std::size_t n = 0;
  for (std::string line; n < kept && std::getline(in, line);) {
    if (line.empty() || line.front() != '{' || line.back() != '}') continue;  // a row cut by a crash
    if (n++ > 0) out += ',';
    out += line;
  }
  out += ']';
  return out;
}

void RunArchive::begin(const std::string& task_id, const std::string& state, double stamp_s) {
  const fs::path dir = folder_ / task_id;
  std::error_code ec;
  fs::remove_all(dir, ec);
  fs::create_directories(dir, ec);
  Run& run = runs_[task_id];
  run.meta = {{"task_id", task_id}, {"state", state}, {"started", stamp_s}, {"ended", nullptr},
              {"first", nullptr},   {"last", nullptr}, {"rows", 0},          {"cell_rows", 0},
              {"truncated", false}};
  run.rows.close();
  run.rows.clear();
  run.rows.open(dir / "plots.jsonl", std::ios::trunc);
  run.cell.close();
  run.cell.clear();
  run.cell.open(dir / "cell.jsonl", std::ios::trunc);
  // The run's first cell row: where everything was when it began (later rows are only the changes).
  if (!cell_.empty()) {
    json first = cell_;
    first["t"] = stamp_s;
    append(run, run.cell, "cell_rows", first.dump(-1, ' ', false, json::error_handler_t::replace));
  }
  write_meta(run);
  prune();
}

void RunArchive::finish(Run& run, const std::string& state, double stamp_s) {
  run.meta["state"] = state;
  run.meta["ended"] = stamp_s;
  run.rows.close();
  run.cell.close();
  write_meta(run);
}

void RunArchive::write_meta(const Run& run) const {
  const fs::path dir = folder_ / run.meta["task_id"].get<std::string>();
  const fs::path tmp = dir / "run.json.tmp";
  {
    std::ofstream out(tmp, std::ios::trunc);
    out << run.meta.dump(2) << '\n';
    if (!out) return;  // a full disk: the rows are still there; run.json is rewritten at the run's end
  }
  std::error_code ec;
  fs::rename(tmp, dir / "run.json", ec);
}

void RunArchive::prune() {
  while (runs_.size() > limits_.max_runs) {
    auto oldest = runs_.end();
    for (auto it = runs_.begin(); it != runs_.end(); ++it) {
      if (it->second.rows.is_open()) continue;
      if (oldest == runs_.end() || time_of(it->second.meta, "started") < time_of(oldest->second.meta, "started"))
        oldest = it;
    }
    if (oldest == runs_.end()) return;  // every run is active
    std::error_code ec;
    fs::remove_all(folder_ / oldest->first, ec);
    runs_.erase(oldest);
  }
}

}  // namespace rigger::console
