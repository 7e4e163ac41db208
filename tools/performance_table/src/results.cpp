#include "rigger/performance/results.hpp"

#include <sys/utsname.h>

#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <ctime>
#include <fstream>
#include <iostream>
#include <sstream>
#include <stdexcept>
#include <thread>

namespace rigger::performance {
namespace {

using nlohmann::json;

std::string utc_now() {
  const std::time_t now = std::chrono::system_clock::to_time_t(std::chrono::system_clock::now());
  std::tm tm{};
  gmtime_r(&now, &tm);
  char text[32];
  std::strftime(text, sizeof text, "%Y-%m-%dT%H:%M:%SZ", &tm);
  return text;
}

// The member `key` of `object` as T, or an error naming where it is and what was expected.
template <typename T>
T field(const json& object, const char* key, const std::string& where, const char* expected) {
  const auto it = object.find(key);
  if (it == object.end()) throw std::runtime_error(where + ": missing \"" + key + "\" (" + expected + ")");
  const bool ok = std::is_same_v<T, std::string> ? it->is_string() : it->is_number();
  if (!ok) throw std::runtime_error(where + ": \"" + key + "\" must be " + expected);
  return it->get<T>();
}

BenchResult ours_from_json(const json& in, const std::string& where) {
  BenchResult r;
  r.bench = field<std::string>(in, "bench", where, "a string");
  r.title = field<std::string>(in, "title", where, "a string");
  r.measured_utc = field<std::string>(in, "measured_utc", where, "an ISO 8601 string");
  const auto& machine = in.at("machine");
  r.machine.cpu = field<std::string>(machine, "cpu", where + "/machine", "a string");
  r.machine.cores = field<int>(machine, "cores", where + "/machine", "a number");
  r.machine.kernel = field<std::string>(machine, "kernel", where + "/machine", "a string");
  const auto& figures = in.at("figures");
  if (!figures.is_array()) throw std::runtime_error(where + ": \"figures\" must be an array");
  for (std::size_t i = 0; i < figures.size(); ++i) {
    const std::string at = where + "/figures/" + std::to_string(i);
    Figure f;
    f.name = field<std::string>(figures[i], "name", at, "a string");
    f.value = field<double>(figures[i], "value", at, "a number");
    f.unit = field<std::string>(figures[i], "unit", at, "a string");
    if (figures[i].contains("reference")) {
      f.reference = field<std::string>(figures[i], "reference", at, "a string");
      f.reference_value = field<double>(figures[i], "reference_value", at, "a number");
    }
    r.figures.push_back(std::move(f));
  }
  return r;
}

// Google Benchmark's --benchmark_out JSON: the context names the program and the machine; each
// benchmark (aggregates are skipped when repetitions ran, the mean is kept) gives its real time and
// its user counters.
BenchResult google_from_json(const json& in, const std::string& where) {
  const auto& context = in.at("context");
  BenchResult r;
  const std::string executable = field<std::string>(context, "executable", where + "/context", "a string");
  r.bench = std::filesystem::path(executable).filename().string();
  r.title = "Google Benchmark micro-benchmarks; the rows of one table ran in the same process";
  r.measured_utc = field<std::string>(context, "date", where + "/context", "a string");
  r.machine.cores = field<int>(context, "num_cpus", where + "/context", "a number");
  // Google Benchmark names the host, not the processor: the file is read on the machine that wrote it
  // (test/bench/run converts it at once), so this machine's description is the bench's.
  const Machine here = this_machine();
  r.machine.cpu = here.cpu;
  r.machine.kernel = here.kernel;
  for (const auto& b : in.at("benchmarks")) {
    const std::string run_type = b.value("run_type", "iteration");
    if (run_type == "aggregate" && b.value("aggregate_name", "") != "mean") continue;
    const std::string name = field<std::string>(b, "name", where + "/benchmarks", "a string");
    r.figures.push_back({name, field<double>(b, "real_time", where + "/benchmarks", "a number"),
                         b.value("time_unit", "ns"), "", 0});
    static const std::vector<std::string> kNotCounters = {
        "name", "family_index", "per_family_instance_index", "run_name", "run_type", "repetitions",
        "repetition_index", "threads", "iterations", "real_time", "cpu_time", "time_unit",
        "aggregate_name", "aggregate_unit", "label", "error_occurred", "error_message"};
    for (const auto& [key, value] : b.items()) {
      if (!value.is_number() ||
          std::find(kNotCounters.begin(), kNotCounters.end(), key) != kNotCounters.end())
        continue;
      r.figures.push_back({name + " " + key, value.get<double>(), key, "", 0});
    }
  }
  return r;
}

std::string figure_text(double v) {
  std::ostringstream out;
  const double a = std::abs(v);
  out.setf(std::ios::fixed);
  out.precision(a >= 100 ? 0 : a >= 10 ? 1 : a >= 1 ? 2 : 3);
  out << v;
  return out.str();
}

}  // namespace

Machine this_machine() {
  Machine m;
  std::ifstream cpuinfo("/proc/cpuinfo");
  for (std::string line; std::getline(cpuinfo, line);) {
    if (line.rfind("model name", 0) == 0) {
      m.cpu = line.substr(line.find(':') + 2);
      break;
    }
  }
  m.cores = static_cast<int>(std::thread::hardware_concurrency());
  utsname u{};
  if (uname(&u) == 0) m.kernel = std::string(u.sysname) + " " + u.release;
  return m;
}

json to_json(const BenchResult& r) {
  json figures = json::array();
  for (const auto& f : r.figures) {
    json item = {{"name", f.name}, {"value", f.value}, {"unit", f.unit}};
    if (!f.reference.empty()) {
      item["reference"] = f.reference;
      item["reference_value"] = f.reference_value;
    }
    figures.push_back(std::move(item));
  }
  return {{"bench", r.bench},
          {"title", r.title},
          {"measured_utc", r.measured_utc},
          {"machine", {{"cpu", r.machine.cpu}, {"cores", r.machine.cores}, {"kernel", r.machine.kernel}}},
          {"figures", std::move(figures)}};
}

BenchResult result_from_json(const json& in, const std::string& where) {
  if (!in.is_object()) throw std::runtime_error(where + ": expected a JSON object");
  try {
    return in.contains("benchmarks") ? google_from_json(in, where) : ours_from_json(in, where);
  } catch (const json::exception& e) {
    throw std::runtime_error(where + ": " + e.what());
  }
}

std::vector<BenchResult> read_results(const std::filesystem::path& folder) {
  constexpr std::uintmax_t kMaxFileBytes = 4u << 20;
  std::vector<BenchResult> results;
  for (const auto& entry : std::filesystem::directory_iterator(folder)) {
    if (entry.path().extension() != ".json") continue;
    const std::string where = entry.path().string();
    if (entry.file_size() > kMaxFileBytes) throw std::runtime_error(where + ": larger than 4 MiB");
    std::ifstream in(entry.path());
    const json parsed = json::parse(in, nullptr, false);
    if (parsed.is_discarded()) throw std::runtime_error(where + ": not valid JSON");
    results.push_back(result_from_json(parsed, where));
  }
  std::sort(results.begin(), results.end(),
            [](const BenchResult& a, const BenchResult& b) { return a.bench < b.bench; });
  return results;
}

std::string performance_markdown(const std::vector<BenchResult>& results) {
  std::ostringstream md;
  md << "# Performance\n\n"
        "<!-- Generated by test/bench/run from test/bench/results/*.json; do not edit. -->\n\n"
        "The latest figures of every benchmark, each next to the reference the same run measured on the\n"
        "same machine (ratio = figure / reference). Run `test/bench/run [name]` to measure again: it\n"
        "rewrites the bench's file in `test/bench/results/` and this page. How each bench works and what\n"
        "it targets is in its source (`test/bench/`, the services' `bench/` folders) and in\n"
        "[testing.md](testing.md).\n\n";
  md << "| bench | measured (UTC) | machine |\n| --- | --- | --- |\n";
  for (const auto& r : results)
    md << "| [`" << r.bench << "`](#" << r.bench << ") | " << r.measured_utc << " | " << r.machine.cpu << ", "
       << r.machine.cores << " cores, " << r.machine.kernel << " |\n";
  for (const auto& r : results) {
    md << "\n## " << r.bench << "\n\n" << r.title << "\n\n";
    md << "| figure | value | unit | reference (same run) | reference value | ratio |\n"
          "| --- | ---: | --- | --- | ---: | ---: |\n";
    for (const auto& f : r.figures) {
      md << "| " << f.name << " | " << figure_text(f.value) << " | " << f.unit << " | ";
      if (f.reference.empty()) {
        md << " |  |  |\n";
      } else {
        md << f.reference << " | " << figure_text(f.reference_value) << " | "
           << (f.reference_value != 0 ? figure_text(f.value / f.reference_value) : std::string("")) << " |\n";
      }
    }
  }
  return md.str();
}

Report::Report(std::string bench, std::string title) {
  result_.bench = std::move(bench);
  result_.title = std::move(title);
}

std::filesystem::path Report::save() {
  const char* folder = std::getenv("RIGGER_BENCH_RESULTS");
  if (folder == nullptr || *folder == '\0') return {};
  result_.measured_utc = utc_now();
  result_.machine = this_machine();
  const std::filesystem::path path = std::filesystem::path(folder) / (result_.bench + ".json");
  const std::filesystem::path tmp = path.string() + ".tmp";
  {
    std::ofstream out(tmp);
    out << to_json(result_).dump(2) << "\n";
    if (!out) throw std::runtime_error(tmp.string() + ": cannot write the bench's results");
  }
  std::filesystem::rename(tmp, path);
  return path;
}

int save_for_main(Report& report) {
  try {
    report.save();
    return 0;
  } catch (const std::exception& e) {  // std::filesystem_error from the rename, too
    std::cerr << e.what() << "\n";
    return 1;
  }
}

}  // namespace rigger::performance
