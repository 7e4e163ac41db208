// Memory of the console after an hour of live plots: two console processes on one domain, one with 1
// browser-less client and one with --clients of them (each client reads the plot stream and the event
// stream, as a page does), fed by this process over DDS with every topic the console plots or draws
// (wrench, crane state, robot state, admittance state, a tracked entity): 72,000 samples per series,
// an hour of 20 Hz data, their stamps 50 ms apart. The samples come faster than 20 Hz (--rate), and the
// console's plot rate is set to the same rate, so that each sample still makes one plot row: the plot
// log holds an hour's rows at the end, as it would after an hour at 20 Hz. Its resident memory (VmRSS,
// /proc/PID/status) at 0, 6, 30 and 60 minutes of data, and its peak (VmHWM), next to its resident
// memory idle (no sample, no client) in the same run. Every plot row must reach every client, in
// order, with no stream dropped; else the exit code is 1.
//
// What the accelerated feed does not reproduce: the 3D cell's events are made at a fixed 10 Hz of wall
// time (console_node.cpp), so the run holds rate/20 times fewer of them than an hour would.
//
//   build/bench/bench_console_memory [--rate 100] [--clients 4] [--minutes 60]
#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <memory>
#include <mutex>
#include <string>
#include <string_view>
#include <thread>
#include <vector>

#include "bench_util.hpp"
#include "console_bench.hpp"
#include "rigger/base/time.hpp"
#include "rigger/dds/conversions.hpp"
#include "rigger/dds/pubsub.hpp"
#include "rigger/protocol/admittance.hpp"
#include "rigger/protocol/crane.hpp"
#include "rigger/protocol/robot.hpp"
#include "rigger/protocol/world.hpp"
#include "rigger/testing/cell.hpp"

// Last: its system headers define macros that break Eigen's (pulled in above).
#include <httplib.h>

namespace {

/// VmRSS and VmHWM of `pid` in MiB (/proc/PID/status); zeros when unreadable.
struct Memory {
  double rss_mib = 0, hwm_mib = 0;
};
Memory memory_of(pid_t pid) {
  Memory m;
  std::ifstream in("/proc/" + std::to_string(pid) + "/status");
  for (std::string line; std::getline(in, line);) {
    if (line.rfind("VmRSS:", 0) == 0) m.rss_mib = std::stod(line.substr(6)) / 1024.0;
    if (line.rfind("VmHWM:", 0) == 0) m.hwm_mib = std::stod(line.substr(6)) / 1024.0;
  }
  return m;
}

/// A browser-less SSE client of `path`: checks that the events come numbered one after the other from
/// its first, with no reset, and keeps the first one's number and the last one's number and data.
class Stream {
 public:
  Stream(std::uint16_t port, const std::string& path) : client_("127.0.0.1", port) {
    client_.set_read_timeout(3600, 0);
    thread_ = std::thread([this, path] {
      std::string buffer;
      client_.Get(
          path.c_str(), httplib::Headers{},
          [this](const httplib::Response& res) {
            status_ = res.status;
            return true;
          },
          [this, &buffer](const char* data, std::size_t n) {
            rigger::bench::take_sse_events(buffer, data, n, [this](std::string_view event) { take(event); });
            return !stopping_;
          });
      ended_ = true;
    });
  }
  ~Stream() { stop(); }
  /// Ends the stream; true when it was still open (the console had not dropped it).
  bool stop() {
    const bool open = !ended_;
    stopping_ = true;
    client_.stop();
    if (thread_.joinable()) thread_.join();
    return open;
  }
  int status() const { return status_; }
  std::uint64_t first_seq() const { return first_seq_; }
  std::uint64_t last_seq() const { return last_seq_; }
  std::uint64_t count() const { return count_; }
  std::uint64_t data_bytes() const { return data_bytes_; }  ///< of all the events' data lines
  int faults() const { return faults_; }  ///< events out of order, resets
  std::string last_data() const {
    std::lock_guard lock(mutex_);
    return last_data_;
  }

 private:
  void take(std::string_view event) {
    if (event.rfind(":", 0) == 0) return;  // keep-alive
    std::uint64_t seq = 0;
    std::string_view data;
    bool reset = false;
    for (std::size_t start = 0; start < event.size();) {
      std::size_t end = event.find('\n', start);
      if (end == std::string_view::npos) end = event.size();
      const std::string_view line = event.substr(start, end - start);
      if (line.rfind("id: ", 0) == 0) seq = std::strtoull(std::string(line.substr(line.find(':', 4) + 1)).c_str(), nullptr, 10);
      if (line == "event: reset") reset = true;
      if (line.rfind("data: ", 0) == 0) data = line.substr(6);
      start = end + 1;
    }
    if (count_ == 0) first_seq_ = seq;
    if (reset || (count_ > 0 && seq != last_seq_ + 1)) ++faults_;
    last_seq_ = seq;
    ++count_;
    data_bytes_ += data.size();
    std::lock_guard lock(mutex_);
    last_data_ = std::string(data);
  }

  httplib::Client client_;
  std::atomic<int> status_{0}, faults_{0};
  std::atomic<std::uint64_t> first_seq_{0}, last_seq_{0}, count_{0}, data_bytes_{0};
  std::atomic<bool> stopping_{false}, ended_{false};
  mutable std::mutex mutex_;
  std::string last_data_;
  std::thread thread_;
};

/// One console and its clients.
struct Watched {
  std::string label;
  rigger::bench::BenchConsole console;
  int clients = 0;
  std::vector<std::unique_ptr<Stream>> plots, events;
  Memory idle;
  std::vector<Memory> points;
};

}  // namespace

int main(int argc, char** argv) {
  using namespace std::chrono_literals;
  namespace dds = rigger::dds;
  const int rate_hz = std::clamp(rigger::bench::int_option(argc, argv, "--rate", 100), 20, 100);
  const int many = rigger::bench::int_option(argc, argv, "--clients", 4);
  const int minutes = std::max(10, rigger::bench::int_option(argc, argv, "--minutes", 60));
  const long samples = 20L * 60 * minutes;  // per series, at 20 Hz
  const std::vector<int> at_minutes = {0, minutes / 10, minutes / 2, minutes};

  rigger::testing::Cell cell;
  const nlohmann::json settings{{"plot_rate_hz", rate_hz}, {"max_streams", 2 * many + 4}};
  std::vector<Watched> consoles;
  consoles.push_back({"1 client", rigger::bench::start_console(cell, {{"bench", rigger::console::Role::kViewer}},
                                                               "console-1", settings), 1, {}, {}, {}, {}});
  consoles.push_back({std::to_string(many) + " clients",
                      rigger::bench::start_console(cell, {{"bench", rigger::console::Role::kViewer}}, "console-n",
                                                   settings),
                      many, {}, {}, {}, {}});
  if (!cell.wait_ready({"console-1", "console-n"}, 30s)) {
    std::fprintf(stderr, "the consoles did not become ready\n%s", cell.logs().c_str());
    return 1;
  }
  auto& participant = cell.participant();
  dds::Writer<rigger_sensing_WrenchStamped> wrench(participant, rigger::protocol::robot::kWrench);
  dds::Writer<rigger_crane_CraneState> crane(participant, rigger::protocol::crane::kState);
  dds::Writer<rigger_robot_RobotState> robot(participant, rigger::protocol::robot::kState);
  dds::Writer<rigger_admittance_AdmittanceState> admittance(participant, rigger::protocol::admittance::kState);
  dds::Writer<rigger_world_EntityState> entity(participant, rigger::protocol::world::kEntity);
  if (!wrench.wait_for_readers(2, 10s) || !crane.wait_for_readers(2, 10s) || !robot.wait_for_readers(2, 10s) ||
      !admittance.wait_for_readers(2, 10s) || !entity.wait_for_readers(2, 10s)) {
    std::fprintf(stderr, "the consoles' sensor readers did not match\n");
    return 1;
  }

  for (auto& w : consoles) w.idle = memory_of(w.console.process->pid());  // the reference: no sample, no client
  for (auto& w : consoles)
    for (int c = 0; c < w.clients; ++c) {
      const std::string token = "?token=" + w.console.users[0].token;
      w.plots.push_back(std::make_unique<Stream>(w.console.port, "/api/plots/stream" + token));
      w.events.push_back(std::make_unique<Stream>(w.console.port, "/api/events" + token));
    }
  const auto streaming = [&] {
    for (const auto& w : consoles)
      for (int c = 0; c < w.clients; ++c)
        if (w.plots[c]->status() != 200 || w.events[c]->status() != 200) return false;
    return true;
  };
  if (!cell.wait_until(streaming, 10s)) {
    std::fprintf(stderr, "a client's stream did not open (HTTP 200)\n");
    return 1;
  }
  const auto measure = [&] {
    for (auto& w : consoles) w.points.push_back(memory_of(w.console.process->pid()));
  };
  measure();

  // The samples: stamps 50 ms apart from a fixed start, sent at rate_hz.
  const std::string frame = "base", none = "", load = "load", tracker = "vision_tracker", empty_json = "{}";
  const std::int64_t start_ns = 1'800'000'000'000'000'000;
  const auto period = std::chrono::nanoseconds(1'000'000'000 / rate_hz);
  auto next = std::chrono::steady_clock::now();
  std::size_t point = 1;
  for (long i = 1; i <= samples; ++i) {
    const auto stamp = dds::to_wire(rigger::from_unix_ns(start_ns + i * 50'000'000));
    const double phase = 2.0 * M_PI * static_cast<double>(i) / 1200.0;  // a minute-long swing
    rigger_sensing_WrenchStamped w{};
    w.header = {stamp, dds::wire_string(frame)};
    w.wrench.force = {10.0 * std::sin(phase), 5.0 * std::cos(phase), -40.0};
    rigger_crane_CraneState c{};
    c.header = {stamp, dds::wire_string(frame)};
    c.position_m[0] = std::sin(phase);
    c.position_m[2] = 2.0;
    c.velocity_mps[0] = 0.1 * std::cos(phase);
    c.fault_text = dds::wire_string(none);
    rigger_robot_RobotState r{};
    r.header = {stamp, dds::wire_string(frame)};
    r.tool_pose.orientation.w = 1.0;
    r.flange_pose.orientation.w = 1.0;
    r.tool_pose.position = {0.5, 0.2 * std::sin(phase), 1.0};
    r.tool_twist.linear = {0.0, 0.02 * std::cos(phase), 0.0};
    r.fault = dds::wire_string(none);
    rigger_admittance_AdmittanceState a{};
    a.header = {stamp, dds::wire_string(frame)};
    a.fault_code = dds::wire_string(none);
    a.fault_text = dds::wire_string(none);
    a.servo_error_m = 0.001 * std::sin(phase);
    rigger_world_EntityState e{};
    e.entity_id = dds::wire_string(load);
    e.kind = rigger_world_ENTITY_OBJECT;
    e.parent_frame = dds::wire_string(frame);
    e.has_pose = true;
    e.pose.pose.position = {std::sin(phase), 0.0, 1.5};
    e.pose.pose.orientation.w = 1.0;
    e.stamp = stamp;
    e.source = dds::wire_string(tracker);
    e.features_json = dds::wire_string(empty_json);
    e.attributes_json = dds::wire_string(empty_json);
    wrench.write(w);
    crane.write(c);
    robot.write(r);
    admittance.write(a);
    entity.write(e);
    if (point < at_minutes.size() && i == 20L * 60 * at_minutes[point]) {
      measure();
      ++point;
    }
    next += period;
    std::this_thread::sleep_until(next);  // the publisher's pace, not a synchronisation
  }

  // The last rows: every client of a console has the same last row, and the console has none after it.
  const auto delivered = [&](const Watched& w) {
    const std::string last = w.plots[0]->last_data();
    for (const auto& p : w.plots)
      if (p->last_data() != last || p->last_seq() != w.plots[0]->last_seq()) return false;
    const std::size_t comma = last.find(',');
    if (last.size() < 6 || comma == std::string::npos) return false;
    httplib::Client http("127.0.0.1", w.console.port);
    char from[64];
    std::snprintf(from, sizeof from, "%.4f", std::stod(last.substr(5, comma - 5)) + 0.0005);
    http.set_bearer_token_auth(w.console.users[0].token);
    const auto res = http.Get("/api/plots?from=" + std::string(from));
    return res && res->status == 200 && res->body == "[]";
  };
  int failures = 0;
  for (auto& w : consoles)
    if (!cell.wait_until([&] { return delivered(w); }, 20s)) {
      std::fprintf(stderr, "%s: the clients did not all get the console's last plot row\n", w.label.c_str());
      ++failures;
    }
  std::vector<std::uint64_t> rows;
  for (auto& w : consoles) {
    rows.push_back(w.plots[0]->last_seq());
    for (int c = 0; c < w.clients; ++c) {
      // The plot log was empty when the clients came: each must have every row, from the first.
      if (w.plots[c]->first_seq() != 1 || w.plots[c]->faults() != 0 || w.events[c]->faults() != 0) {
        std::fprintf(stderr, "%s, client %d: %d plot and %d event(s) out of order or reset\n", w.label.c_str(), c,
                     w.plots[c]->faults(), w.events[c]->faults());
        ++failures;
      }
      if (!w.plots[c]->stop() || !w.events[c]->stop()) {
        std::fprintf(stderr, "%s, client %d: the console ended a stream\n", w.label.c_str(), c);
        ++failures;
      }
    }
  }
  const auto stopped = cell.stop_all();
  if (!stopped.ok) {
    std::fprintf(stderr, "%s", stopped.problems.c_str());
    ++failures;
  }

  std::printf(
      "Console memory with %ld samples per series (%d min of 20 Hz data: wrench, crane, robot, admittance, "
      "tracked entity), sent at %d Hz with stamps 50 ms apart, plot rate %d Hz (one row per sample)\n",
      samples, minutes, rate_hz, rate_hz);
  std::printf("%-12s %10s %9s", "", "idle MiB", "rows");
  for (const int m : at_minutes) std::printf(" %8s", (std::to_string(m) + " min").c_str());
  std::printf(" %9s %9s %9s\n", "peak MiB", "0->last", "half->last");
  rigger::performance::Report report(
      "bench_console_memory",
      "Console resident memory (VmRSS) after 0, 6, 30 and 60 minutes of 20 Hz plot data (72,000 samples per series, "
      "sent at " + std::to_string(rate_hz) + " Hz with stamps 50 ms apart), with 1 and " + std::to_string(many) +
          " SSE clients, next to the console idle (no sample, no client) in the same run");
  for (std::size_t k = 0; k < consoles.size(); ++k) {
    const auto& w = consoles[k];
    const double first = w.points.front().rss_mib, half = w.points[2].rss_mib, last = w.points.back().rss_mib;
    std::printf("%-12s %10.1f %9llu", w.label.c_str(), w.idle.rss_mib, static_cast<unsigned long long>(rows[k]));
    for (const auto& p : w.points) std::printf(" %8.1f", p.rss_mib);
    std::printf(" %9.1f %8.2fx %9.2fx\n", w.points.back().hwm_mib, last / first, last / half);
    std::printf("  %s: %s from the first point to the last (%s)\n", w.label.c_str(), last / first <= 1.2 ? "flat" : "growing",
                last / half <= 1.2 ? "flat over the second half" : "still growing over the second half");
    const auto mean = [](const Stream& st) { return st.count() ? double(st.data_bytes()) / st.count() : 0.0; };
    std::printf("  %s: %llu plot rows of %.0f B, %llu events of %.0f B (the 3D cell's, made at 10 Hz of wall time)\n",
                w.label.c_str(), static_cast<unsigned long long>(w.plots[0]->count()), mean(*w.plots[0]),
                static_cast<unsigned long long>(w.events[0]->count()), mean(*w.events[0]));
    for (std::size_t p = 0; p < w.points.size(); ++p)
      report.add({"console RSS, " + w.label + ", " + std::to_string(at_minutes[p]) + " min of data", w.points[p].rss_mib,
                  "MiB", "console RSS idle", w.idle.rss_mib});
    report.add({"console peak RSS (VmHWM), " + w.label, w.points.back().hwm_mib, "MiB", "console RSS idle",
                w.idle.rss_mib});
  }
  if (failures != 0) return 1;
  return rigger::performance::save_for_main(report);
}
