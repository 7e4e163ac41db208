#pragma once
// What the console benchmarks share: the console started on a private domain, and the browser they drive.
#include <cstdint>
#include <fstream>
#include <string>
#include <string_view>
#include <vector>

#include <nlohmann/json.hpp>

#include "../integration/cell_sim_test_support.hpp"
#include "auth.hpp"
#include "rigger/testing/cell.hpp"

namespace rigger::bench {

/// A console process of a Cell.
struct BenchConsole {
  std::uint16_t port = 0;
  std::vector<console::CreatedUser> users;  ///< in the order asked for
  testing::ChildProcess* process = nullptr;
};

/// Starts the console as process "console" of `cell` on a free port, with `users` and no audit log
/// (configuration and users file in the cell's log folder). Does not wait for it to be ready.
inline BenchConsole start_console(testing::Cell& cell, const std::vector<console::NewUser>& users) {
  const std::string dir = cell.log_dir();
  BenchConsole out;
  out.users = console::make_users(dir + "/users.json", users);
  out.port = testing::free_tcp_port();
  std::ofstream(dir + "/console.json") << nlohmann::json{{"port", out.port}, {"users_file", dir + "/users.json"},
                                                         {"audit_log", ""}, {"runs_dir", ""}}.dump();
  out.process = &cell.start("console", "console",
                            {"--id", "console", "--config", dir + "/console.json", "--log-level", "warn"});
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

}  // namespace rigger::bench
