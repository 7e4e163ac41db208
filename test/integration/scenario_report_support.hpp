#pragma once
// What the scenario tests print about a run: the nodes' last statuses and the skills' durations, the times
// the simulator fell behind real time, and the CPU each service used over the insertion.
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <map>
#include <string>
#include <utility>
#include <vector>

#include "rigger/protocol/task_names.hpp"

namespace rigger::testing::scenario {

/// A node's last status.
struct NodeView {
  std::string name, type, executor, code, message;
  int state = -1;
  double started_s = 0.0, finished_s = 0.0;  // wall clock, s since the epoch (0: not yet)
  int runs = 0;                              // times it was seen entering RUNNING
};

/// CPU time per service (s, user + system) and the wall clock at a moment (the insertion's start or end).
struct CpuMark {
  std::chrono::steady_clock::time_point at{};
  std::map<std::string, double> cpu_s;
};

/// The skill nodes of `nodes` with their durations, in start order, as the demo prints them.
inline std::string skill_durations(const std::map<std::string, NodeView>& nodes) {
  std::vector<std::pair<double, std::string>> lines;
  for (const auto& [id, n] : nodes) {
    if (n.type != "Skill" || n.started_s <= 0.0) continue;
    char buf[200];
    const double end = n.finished_s > 0.0 ? n.finished_s : n.started_s;
    std::snprintf(buf, sizeof buf, "  %-32s %-10s %6.1f s  %s", n.name.c_str(),
                  protocol::task::node_state_name(n.state), end - n.started_s, n.code.c_str());
    lines.emplace_back(n.started_s, buf);
  }
  std::sort(lines.begin(), lines.end());
  std::string out;
  for (const auto& [t, l] : lines) out += l + "\n";
  return out;
}

/// The times the simulator fell behind real time and skipped ahead (its log says so, at most every 5 s):
/// then the robot's wrench and state had a gap, which a monitor may report as SENSOR_STALE. Empty when it
/// never did; otherwise a line with the overruns and the worst lag logged.
inline std::string simulator_lag_report(const std::string& log_dir) {
  std::ifstream log(log_dir + "/cell_sim.log");
  const std::string key = "physics behind real time lag_ms=";
  long worst_ms = 0, overruns = 0;
  for (std::string line; std::getline(log, line);) {
    const auto at = line.find(key);
    if (at == std::string::npos) continue;
    worst_ms = std::max(worst_ms, std::strtol(line.c_str() + at + key.size(), nullptr, 10));
    const auto o = line.find("overruns=", at);
    if (o != std::string::npos) overruns = std::strtol(line.c_str() + o + 9, nullptr, 10);
  }
  if (overruns == 0) return "";
  return "  the simulator fell behind real time " + std::to_string(overruns) + " time(s), worst lag logged " +
         std::to_string(worst_ms) + " ms (cell_sim.log): the machine was short of CPU\n";
}

/// What each service's process used of the CPU over the (first) insertion — the 1 kHz wrench, the
/// camera images and the visual servo — in % of one core (/proc/<pid>/stat), with the insertion's wall
/// time and the machine's load average (other work shares it), from the marks at its start and its end.
inline std::string insertion_cpu_report(const CpuMark& started, const CpuMark& ended,
                                        const std::vector<std::string>& services) {
  const double wall_s = std::chrono::duration<double>(ended.at - started.at).count();
  if (wall_s <= 0.0) return "";
  std::ifstream loadavg("/proc/loadavg");
  std::string l1, l5, l15;
  loadavg >> l1 >> l5 >> l15;
  char head[160];
  std::snprintf(head, sizeof head, "  CPU over the insertion (%.1f s, load average %s %s %s), %% of one core:\n",
                wall_s, l1.c_str(), l5.c_str(), l15.c_str());
  std::string out = head;
  double total = 0.0;
  for (const auto& name : services) {
    const auto a = started.cpu_s.find(name), b = ended.cpu_s.find(name);
    if (a == started.cpu_s.end() || b == ended.cpu_s.end()) continue;
    const double percent = 100.0 * (b->second - a->second) / wall_s;
    total += percent;
    char line[120];
    std::snprintf(line, sizeof line, "    %-20s %5.1f %%\n", name.c_str(), percent);
    out += line;
  }
  char sum[80];
  std::snprintf(sum, sizeof sum, "    %-20s %5.1f %%\n", "all services", total);
  return out + sum;
}

}  // namespace rigger::testing::scenario
