// rigger-compose logs: prints a service's (or the supervisor's) log, and follows it with inotify.
#include <errno.h>
#include <signal.h>
#include <string.h>
#include <sys/inotify.h>
#include <unistd.h>

#include <cstdio>
#include <deque>
#include <fstream>
#include <iostream>

#include "command_support.hpp"
#include "rigger/compose/process_util.hpp"

namespace rigger::compose::cli {
namespace {

volatile sig_atomic_t g_follow_stop = 0;

}  // namespace

int logs(const GlobalOptions& g, const std::string& service, bool follow, int last_lines) {
  const ComposeFile file = load(g);
  if (service != "supervisor" && !file.find(service))
    fail("no service named '" + service + "' in " + file.path + " (or use 'supervisor')", kExitUsage);
  const LogLayout layout(file.log_dir);
  const std::string path = service == "supervisor" ? layout.supervisor_log() : layout.service_log(service);
  std::ifstream in(path, std::ios::binary);
  if (!in) fail("no log for " + service + " yet (" + path + ")");

  if (last_lines > 0) {
    std::deque<std::string> tail;
    std::string line;
    while (std::getline(in, line)) {
      tail.push_back(line);
      if (static_cast<int>(tail.size()) > last_lines) tail.pop_front();
    }
    for (const auto& l : tail) std::printf("%s\n", l.c_str());
    in.clear();
  } else {
    std::cout << in.rdbuf();
    in.clear();
  }
  std::fflush(stdout);
  std::cout.flush();
  if (!follow) return kExitOk;

  // Follow with inotify: wake on every write, never poll on a timer.
  const int ino = inotify_init1(IN_CLOEXEC);
  if (ino < 0 || inotify_add_watch(ino, path.c_str(), IN_MODIFY | IN_DELETE_SELF | IN_MOVE_SELF) < 0)
    fail("cannot follow " + path + ": " + strerror(errno));
  struct sigaction sa {};
  sa.sa_handler = [](int) { g_follow_stop = 1; };
  sigaction(SIGINT, &sa, nullptr);
  sigaction(SIGTERM, &sa, nullptr);
  in.seekg(0, std::ios::end);
  auto pos = in.tellg();
  char events[4096];
  while (!g_follow_stop) {
    const ssize_t n = read(ino, events, sizeof events);
    if (n <= 0) {
      if (errno == EINTR) continue;
      break;
    }
    std::ifstream again(path, std::ios::binary);
    again.seekg(0, std::ios::end);
    const auto size = again.tellg();
    if (size < pos) pos = 0;  // truncated or replaced
    again.seekg(pos);
    std::cout << again.rdbuf();
    std::cout.flush();
    pos = size;
  }
  close(ino);
  return kExitOk;
}

}  // namespace rigger::compose::cli
