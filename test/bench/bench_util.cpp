#include "bench_util.hpp"

#include <unistd.h>

#include <algorithm>
#include <array>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <regex>
#include <sstream>
#include <stdexcept>

namespace rigger::bench {

double percentile(std::vector<double> values, double q) {
  if (values.empty()) return 0;
  std::sort(values.begin(), values.end());
  const auto rank = static_cast<size_t>(std::ceil(q * static_cast<double>(values.size())));
  return values[std::min(values.size() - 1, rank == 0 ? 0 : rank - 1)];
}

Quantiles quantiles(const std::vector<double>& values) {
  return {percentile(values, 0.50), percentile(values, 0.90), percentile(values, 0.99)};
}

Quantiles round_trip(const DdsperfLatency& ddsperf) {
  return {ddsperf.p50_us, ddsperf.p90_us, ddsperf.p99_us};
}

Quantiles one_way(const DdsperfLatency& ddsperf) {
  return {ddsperf.p50_us / 2, ddsperf.p90_us / 2, ddsperf.p99_us / 2};
}

void add_quantiles(performance::Report& report, const std::string& what, const Quantiles& q, const std::string& unit,
                   const std::string& reference_name, const Quantiles& reference) {
  const std::pair<const char*, double Quantiles::*> levels[] = {
      {" p50", &Quantiles::p50}, {" p90", &Quantiles::p90}, {" p99", &Quantiles::p99}};
  for (const auto& [suffix, level] : levels) {
    report.add({what + suffix, q.*level, unit, reference_name.empty() ? "" : reference_name + suffix,
                reference_name.empty() ? 0.0 : reference.*level});
  }
}

std::string growth_verdict(double first, double last, double scale) {
  if (!(first > 0)) return "no figure";
  const double growth = last / first;
  char text[96];
  std::snprintf(text, sizeof text, "%.2fx over %.0fx: ", growth, scale);
  if (growth <= 1.2) return std::string(text) + "flat";
  if (growth <= 1.2 * scale) return std::string(text) + "linear or better";
  return std::string(text) + "worse than linear";
}

int int_option(int argc, char** argv, const std::string& name, int fallback) {
  for (int i = 1; i + 1 < argc; i += 2)
    if (name == argv[i]) return std::atoi(argv[i + 1]);
  return fallback;
}

std::string string_option(int argc, char** argv, const std::string& name, const std::string& fallback) {
  for (int i = 1; i + 1 < argc; i += 2)
    if (name == argv[i]) return argv[i + 1];
  return fallback;
}

std::string run_command(const std::string& command) {
  std::string out;
  FILE* p = popen(command.c_str(), "r");
  if (!p) return out;
  std::array<char, 4096> buf;
  size_t n;
  while ((n = fread(buf.data(), 1, buf.size(), p)) > 0) out.append(buf.data(), n);
  pclose(p);
  return out;
}

RunPki::RunPki() {
  char dir_template[] = "/tmp/rigger-bench-pki-XXXXXX";
  if (!mkdtemp(dir_template))
    throw std::runtime_error(std::string("mkdtemp ") + dir_template + ": " + std::strerror(errno));
  folder_ = dir_template;
  pki_ = folder_ + "/pki";
  const std::string make = std::string(RIGGER_SOURCE_DIR) + "/deploy/security/make-pki --catalog " + RIGGER_BINARY_DIR +
                           "/bin/rigger-topic-catalog " + pki_ + " >/dev/null";
  if (std::system(make.c_str()) != 0) {
    std::error_code ignored;
    std::filesystem::remove_all(folder_, ignored);
    throw std::runtime_error(make + " failed");
  }
}

RunPki::~RunPki() {
  std::error_code ignored;
  std::filesystem::remove_all(folder_, ignored);
}

long long voluntary_switches(pid_t pid, const std::string& tid) {
  std::ifstream in("/proc/" + std::to_string(pid) + "/task/" + tid + "/status");
  std::string line;
  while (std::getline(in, line))
    if (line.rfind("voluntary_ctxt_switches:", 0) == 0) return std::stoll(line.substr(line.find(':') + 1));
  return -1;
}

std::pair<long long, long long> wake_ups(pid_t pid) {
  long long all = 0;
  std::error_code ignored;  // a process gone reads as no threads
  for (const auto& entry : std::filesystem::directory_iterator("/proc/" + std::to_string(pid) + "/task", ignored)) {
    const long long n = voluntary_switches(pid, entry.path().filename().string());
    if (n > 0) all += n;
  }
  return {voluntary_switches(pid, std::to_string(pid)), all};
}

std::vector<double> cpu_share(const std::vector<pid_t>& pids, const std::function<void()>& wait) {
  using Clock = std::chrono::steady_clock;
  std::vector<double> before;
  for (pid_t p : pids) before.push_back(cpu_seconds(p));
  const auto wakes_before = wake_ups(pids[0]);
  const auto t0 = Clock::now();
  wait();
  const double wall = std::chrono::duration<double>(Clock::now() - t0).count();
  std::vector<double> share;
  for (std::size_t i = 0; i < pids.size(); ++i) share.push_back((cpu_seconds(pids[i]) - before[i]) / wall);
  const auto wakes_after = wake_ups(pids[0]);
  share.push_back(static_cast<double>(wakes_after.first - wakes_before.first) / wall);
  share.push_back(static_cast<double>(wakes_after.second - wakes_before.second) / wall);
  return share;
}

void add_cpu_share(performance::Report& report, const std::vector<std::string>& names, std::size_t reference,
                   const std::vector<double>& share, const std::string& window) {
  const std::string idle = names[reference] + " CPU, " + window;
  for (std::size_t i = 0; i < names.size(); ++i)
    if (i != reference) report.add({names[i] + " CPU, " + window, share[i], "CPU s/s", idle, share[reference]});
  report.add({names[0] + " loop wake-ups, " + window, share[names.size()], "1/s", "", 0});
  report.add({names[0] + " wake-ups, all threads, " + window, share[names.size() + 1], "1/s", "", 0});
}

DdsperfLatency run_ddsperf_pingpong(std::uint32_t domain, int rate_hz, int payload_bytes, int seconds, bool waitset) {
  const std::string d = std::to_string(domain);
  const std::string mode = waitset ? " waitset" : "";
  // pong runs a little longer than ping so that every ping is answered; both end by themselves (-D).
  const std::string cmd = "ddsperf -i " + d + " -D " + std::to_string(seconds + 3) + " pong" + mode +
                          " >/dev/null 2>&1 & sleep 0.5; ddsperf -i " + d + " -D " + std::to_string(seconds + 1) +
                          " ping " + std::to_string(rate_hz) + "Hz size " + std::to_string(payload_bytes) + mode +
                          " 2>&1; wait";
  DdsperfLatency out;
  out.raw = run_command(cmd);
  // e.g. "[123] 2.000  vm:26591 size 64 mean 46.9us min 18.9us 50% 40.8us 90% 48.6us 99% 150.0us max 2161.7us cnt 1000"
  static const std::regex line(R"(50% ([0-9.]+)us 90% ([0-9.]+)us 99% ([0-9.]+)us max [0-9.]+us cnt ([0-9]+))");
  std::istringstream in(out.raw);
  std::string l;
  double s50 = 0, s90 = 0, s99 = 0;
  bool first = true;
  while (std::getline(in, l)) {
    std::smatch m;
    if (!std::regex_search(l, m, line)) continue;
    if (first) {  // the first second includes discovery and warm-up, as our own warm-up is excluded
      first = false;
      continue;
    }
    const double cnt = std::stod(m[4]);
    s50 += std::stod(m[1]) * cnt;
    s90 += std::stod(m[2]) * cnt;
    s99 += std::stod(m[3]) * cnt;
    out.count += static_cast<std::uint64_t>(cnt);
  }
  if (out.count > 0) {
    const double c = static_cast<double>(out.count);
    out.p50_us = 2 * s50 / c;  // ddsperf reports (t_now - t_sent) / 2
    out.p90_us = 2 * s90 / c;
    out.p99_us = 2 * s99 / c;
  }
  return out;
}

}  // namespace rigger::bench
