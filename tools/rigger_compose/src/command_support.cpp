#include "command_support.hpp"

#include <signal.h>

#include <algorithm>
#include <cctype>
#include <cstdio>
#include <cstdlib>
#include <stdexcept>

#include "rigger/base/install.hpp"
#include "rigger/compose/process_util.hpp"
#include "rigger/compose/security.hpp"
#include "rigger/compose/status_file.hpp"

namespace rigger::compose::cli {

void fail(const std::string& message, int code) { throw CommandError{message, code}; }

ComposeFile load(const GlobalOptions& g) {
  ParseOptions opt;
  opt.domain = g.domain;
  // Without a bin_dir in the file, the services are the ones beside this rigger-compose (build/bin or
  // <prefix>/bin): an installed tree runs its own binaries wherever it was moved.
  opt.default_bin_dir = executable_path().parent_path().string();
  ComposeFile file = load_compose(g.file.empty() ? find_data_path("deploy/compose.yaml").path.string() : g.file, opt);
  if (g.secure) {
    try {
      apply_security(file, default_security_dir());
    } catch (const std::runtime_error& e) {
      fail(e.what(), kExitUsage);
    }
  }
  return file;
}

std::string host_option(const GlobalOptions& g) {
  const char* env = std::getenv("RIGGER_HOST");
  const std::string host = !g.host.empty() ? g.host : env ? env : "";
  // It names a lock file and is matched against `host:`: a host name, nothing else.
  const bool valid = host.size() <= 253 && std::all_of(host.begin(), host.end(), [](char c) {
    return std::isalnum(static_cast<unsigned char>(c)) || c == '-' || c == '.' || c == '_';
  });
  if (!valid) fail("--host / $RIGGER_HOST '" + host + "' is not a host name (letters, digits, '-', '.', '_')", kExitUsage);
  return host;
}

double seconds_since(Clock::time_point t) { return std::chrono::duration<double>(Clock::now() - t).count(); }

void use_dds_config(const ComposeFile& file) {
  if (!file.dds_config.empty()) setenv("CYCLONEDDS_URI", file.dds_uri().c_str(), 1);
}

// Services whose supervisor died without stopping them (SIGKILL, crash): they are still listed with
// their PIDs in its last status file. Stopped like the supervisor would, in reverse start order, after
// checking that each PID still runs that service (its command line has `--id <name>`), so a recycled
// PID is never signalled. Returns how many were found.
int stop_orphans(const ComposeFile& file, const std::string& log_dir) {
  const auto st = read_status_file(LogLayout(log_dir).status_file());
  if (!st) return 0;
  int found = 0;
  for (auto it = st->services.rbegin(); it != st->services.rend(); ++it) {
    if (!it->local || it->pid <= 0 || !process_alive(it->pid)) continue;
    const auto cmdline = read_text_file("/proc/" + std::to_string(it->pid) + "/cmdline").value_or("");
    if (cmdline.find(std::string("--id") + '\0' + it->name + '\0') == std::string::npos) continue;
    ++found;
    const auto* def = file.find(it->name);
    const auto timeout = def ? def->stop_timeout : std::chrono::milliseconds(5000);
    std::printf("  %s (pid %d) outlived its supervisor: SIGINT\n", it->name.c_str(), it->pid);
    std::fflush(stdout);
    send_signal(it->pid, SIGINT);
    if (!wait_for_exit(it->pid, timeout)) {
      std::printf("  %s (pid %d) did not stop within %.1f s: SIGKILL\n", it->name.c_str(), it->pid,
                  std::chrono::duration<double>(timeout).count());
      send_signal(it->pid, SIGKILL);
      wait_for_exit(it->pid, std::chrono::milliseconds(2000));
    }
  }
  return found;
}

}  // namespace rigger::compose::cli
