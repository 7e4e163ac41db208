// Idle CPU of the console (target: "idle console CPU <= 1.5x an idle DDS participant"): the console
// process on a private domain with no task, CPU seconds per wall second (/proc/PID/stat utime+stime)
// over --seconds, with no client, with one browser-less client on the event stream (/api/events) and
// with a second one on the plot stream (/api/plots/stream), next to an idle DDS participant (ddsperf
// pong, nobody pinging) and an idle rigger service (echo) measured over the same windows. Also the
// console's wake-ups per second (voluntary context switches: its work loop's thread, all its threads).
//
//   build/bench/bench_console_idle [--seconds 20]
#include <algorithm>
#include <atomic>
#include <cstdio>
#include <string>
#include <thread>
#include <vector>

#include "bench_util.hpp"
#include "console_bench.hpp"
#include "rigger/testing/cell.hpp"

// Last: its system headers define macros that break Eigen's (pulled in above).
#include <httplib.h>

namespace {

/// A browser-less SSE client: reads `path` until stopped, counting what arrives.
class StreamClient {
 public:
  StreamClient(std::uint16_t port, const std::string& path) : client_("127.0.0.1", port) {
    client_.set_read_timeout(3600, 0);
    thread_ = std::thread([this, path] {
      client_.Get(
          path.c_str(), httplib::Headers{},
          [this](const httplib::Response& res) {
            status_ = res.status;
            return true;
          },
          [this](const char*, std::size_t n) {
            bytes_ += n;
            return true;
          });
    });
  }
  ~StreamClient() {
    client_.stop();
    thread_.join();
  }
  int status() const { return status_; }
  std::size_t bytes() const { return bytes_; }

 private:
  httplib::Client client_;
  std::atomic<int> status_{0};
  std::atomic<std::size_t> bytes_{0};
  std::thread thread_;
};

}  // namespace

int main(int argc, char** argv) {
  using namespace std::chrono_literals;
  const int seconds = rigger::bench::int_option(argc, argv, "--seconds", 20);

  rigger::testing::Cell cell;
  const auto console = rigger::bench::start_console(cell, {{"bench", rigger::console::Role::kViewer}});
  const auto& users = console.users;
  const std::uint16_t port = console.port;
  auto& echo = cell.start("echo", "echo", {"--id", "echo", "--log-level", "warn"});
  // An idle DDS participant on the same domain and configuration: pong, with nobody pinging.
  auto& ddsperf = cell.start("ddsperf", "/usr/bin/ddsperf",
                             {"-i", std::to_string(cell.domain_id()), "-D", std::to_string(4 * seconds + 60), "pong"},
                             false);
  if (!cell.wait_ready({"console", "echo"}, 30s)) {
    std::fprintf(stderr, "the services did not become ready\n%s", cell.logs().c_str());
    return 1;
  }
  auto idle = [&](int s) {
    bool over = false;
    const auto timer = cell.loop().after(std::chrono::seconds(s), [&] { over = true; });
    cell.wait_until([&] { return over; }, std::chrono::seconds(s + 5));
    cell.loop().cancel(timer);
  };
  idle(2);  // discovery settles

  const std::vector<pid_t> pids = {console.process->pid(), ddsperf.pid(), echo.pid()};
  std::printf("Idle CPU (CPU s per wall s, /proc/PID/stat utime+stime, %d s per row, the same windows for all)\n",
              seconds);
  std::printf("%-36s %10s %10s %8s %10s %8s %15s %15s\n", "", "console", "ddsperf", "ratio", "echo", "ratio",
              "console loop/s", "console all/s");
  rigger::performance::Report results(
      "bench_console_idle", "Idle CPU of the console (CPU s per wall s, /proc/PID/stat) with 0, 1 and 2 SSE clients, " +
                                std::to_string(seconds) +
                                " s per row, next to an idle DDS participant (ddsperf pong) over the same windows");
  auto row = [&](const char* label) {
    const auto s = rigger::bench::cpu_share(pids, [&] { idle(seconds); });
    std::printf("%-36s %10.4f %10.4f %7.2fx %10.4f %7.2fx %15.1f %15.1f\n", label, s[0], s[1],
                s[0] / std::max(1e-9, s[1]), s[2], s[0] / std::max(1e-9, s[2]), s[3], s[4]);
    std::fflush(stdout);
    rigger::bench::add_cpu_share(results, {"console", "ddsperf pong", "echo"}, 1, s, label);
  };
  row("no client");
  int failures = 0;
  {
    StreamClient events(port, "/api/events?token=" + users[0].token);
    row("1 SSE client (/api/events)");
    {
      StreamClient plots(port, "/api/plots/stream?token=" + users[0].token);
      row("2 SSE clients (+ /api/plots/stream)");
      if (plots.status() != 200) ++failures;
    }
    if (events.status() != 200) ++failures;
  }
  if (failures > 0) std::fprintf(stderr, "%d stream(s) did not answer 200\n", failures);
  cell.stop("ddsperf", SIGINT, 5s);
  const auto report = cell.stop_all();
  if (!report.ok) std::fprintf(stderr, "%s", report.problems.c_str());
  if (failures != 0 || !report.ok) return 1;
  return rigger::performance::save_for_main(results);
}
