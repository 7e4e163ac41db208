#pragma once
// What the console benchmarks share: the console started on a private domain, the browser they drive
// and the figures its scripts print.
#include <cstdint>
#include <cstdio>
#include <fstream>
#include <regex>
#include <sstream>
#include <string>
#include <string_view>
#include <vector>

#include <nlohmann/json.hpp>

#include "../integration/cell_sim_test_support.hpp"
#include "auth.hpp"
#include "rigger/performance/results.hpp"
#include "rigger/testing/cell.hpp"

namespace rigger::bench {

/// A console process of a Cell.
struct BenchConsole {
  std::uint16_t port = 0;
  std::vector<console::CreatedUser> users;  ///< in the order asked for
  testing::ChildProcess* process = nullptr;
};

/// Starts the console as process and service `name` of `cell` on a free port, with `users`, no audit log
/// and the settings of `extra` (configuration and users file in the cell's log folder). Does not wait
/// for it to be ready.
inline BenchConsole start_console(testing::Cell& cell, const std::vector<console::NewUser>& users,
                                  const std::string& name = "console",
                                  const nlohmann::json& extra = nlohmann::json::object()) {
  const std::string dir = cell.log_dir();
  const std::string config = dir + "/" + name + ".json", users_file = dir + "/" + name + "-users.json";
  BenchConsole out;
  out.users = console::make_users(users_file, users);
  out.port = testing::free_tcp_port();
  nlohmann::json settings{{"port", out.port}, {"users_file", users_file}, {"audit_log", ""}, {"runs_dir", ""}};
  settings.update(extra);
  std::ofstream(config) << settings.dump();
  out.process = &cell.start(name, "console", {"--id", name, "--config", config, "--log-level", "warn"});
  return out;
}

/// Appends `n` bytes of a Server-Sent Event stream to `buffer` and calls `event(text)` with the text of
/// each event now complete in it (its "id", "event" and "data" lines); keeps the rest for the next call.
template <typename Event>
void take_sse_events(std::string& buffer, const char* data, std::size_t n, Event&& event) {
  buffer.append(data, n);
  for (std::size_t end; (end = buffer.find("\n\n")) != std::string::npos; buffer.erase(0, end + 2))
    event(std::string_view(buffer.data(), end));
}

/// The npm packages of the console's pages (playwright-core), or "" (with the reason on stderr) when
/// they or /usr/bin/chromium are missing.
inline std::string browser_modules() {
  const std::string modules = std::string(RIGGER_SOURCE_DIR) + "/services/console/web/node_modules";
  if (!std::ifstream("/usr/bin/chromium") || !std::ifstream(modules + "/playwright-core/index.mjs")) {
    std::fprintf(stderr, "needs /usr/bin/chromium and %s (deploy/setup runs npm ci)\n", modules.c_str());
    return "";
  }
  return modules;
}

/// One row of a browser script's table of figures (test/bench/*/tree.mjs print them): its label, its
/// count column (-1 when empty) and its figures in ms, in the table's order (p50, p90, [p99,] max; a sum
/// row has one).
struct BrowserRow {
  std::string label;
  long count = -1;
  std::vector<double> ms;
};

/// The rows of figures in a browser script's output: a label, two spaces or more, an optional count,
/// numbers, and an optional note after three spaces.
inline std::vector<BrowserRow> browser_rows(const std::string& log) {
  static const std::regex kRow(R"(^(\S.*?)\s{2,}(\d*)\s+([0-9.]+(?:\s+[0-9.]+)*)(?:\s{3}.*)?$)");
  std::vector<BrowserRow> rows;
  std::istringstream in(log);
  for (std::string line; std::getline(in, line);) {
    std::smatch m;
    if (!std::regex_match(line, m, kRow)) continue;
    BrowserRow row{m[1], m[2].length() > 0 ? std::stol(m[2]) : -1, {}};
    std::istringstream numbers(m[3]);
    for (double v; numbers >> v;) row.ms.push_back(v);
    rows.push_back(std::move(row));
  }
  return rows;
}

/// A count that browser_row() takes as matching any.
constexpr long kAnyCount = -2;

/// The row of `rows` labelled `label` with count `count` (or kAnyCount) and at least `figures` figures,
/// or nullptr, saying which on stderr.
inline const BrowserRow* browser_row(const std::vector<BrowserRow>& rows, const std::string& label, long count,
                                     std::size_t figures) {
  for (const auto& r : rows)
    if (r.label == label && (count == kAnyCount || r.count == count) && r.ms.size() >= figures) return &r;
  std::fprintf(stderr, "the browser's output has no row '%s' for %ld with %zu figures\n", label.c_str(), count,
               figures);
  return nullptr;
}

/// Adds the row `label` with count `count` to `report` as "`name` <level>" in ms, one figure per entry of
/// `levels` (the table's columns; "" for a row of one figure), each next to the same column of the row
/// `reference_label` with count `reference_count` ("`reference_name` <level>") when `reference_name` is not empty.
/// False when a row is missing (browser_row).
inline bool add_browser_row(performance::Report& report, const std::vector<BrowserRow>& rows,
                            const std::vector<std::string>& levels, const std::string& name, const std::string& label,
                            long count, const std::string& reference_name = "", const std::string& reference_label = "",
                            long reference_count = -1) {
  const BrowserRow* row = browser_row(rows, label, count, levels.size());
  const BrowserRow* reference =
      reference_name.empty() ? nullptr : browser_row(rows, reference_label, reference_count, levels.size());
  if (!row || (!reference_name.empty() && !reference)) return false;
  for (std::size_t i = 0; i < levels.size(); ++i) {
    const std::string suffix = levels[i].empty() ? "" : " " + levels[i];
    report.add({name + suffix, row->ms[i], "ms", reference ? reference_name + suffix : "",
                reference ? reference->ms[i] : 0.0});
  }
  return true;
}

}  // namespace rigger::bench
