// The Tasks page with a large tree (target: "a 10,000-node recipe's tree shown in chromium in under
// 1 s and following 1,000 node changes per second without falling behind"). A task controller, a
// scripted executor serving Localize leaves (SUCCESS at once) and the console run on a private DDS
// domain; the controller runs a 10-node recipe (the reference) and a --nodes recipe (a Sequence of
// Sequences of 100 Localize leaves) to the end, so the console holds every node's status. Then headless
// Debian chromium (playwright-core, test/bench/console/tree.mjs) opens the Tasks page and times, in the
// page, a click on each task until its whole tree is drawn and laid out (and the frame after it), and
// then follows node changes that this process writes on rigger/task/node_status at --rate per second
// for --seconds (leaves of the large task going RUNNING, and 100 changes later SUCCESS, each change
// with a numbered message): the lag from each change's stamp until the page's tree shows it,
// per second of the run (growing lag = falling behind) and how many were shown. The same changes
// received as SSE events by a browser-less client here are the reference of the same run.
//
//   build/bench/bench_console_tree [--nodes 10000] [--trials 5] [--rate 1000] [--seconds 10]
#include <atomic>
#include <cstdio>
#include <fstream>
#include <map>
#include <numeric>
#include <string>
#include <string_view>
#include <thread>
#include <vector>

#include <nlohmann/json.hpp>

#include "bench_util.hpp"
#include "console_bench.hpp"
#include "rigger/dds/conversions.hpp"
#include "rigger/dds/pubsub.hpp"
#include "rigger/protocol/task.hpp"
#include "rigger/testing/cell.hpp"
#include "rigger/testing/process.hpp"

// Last: its system headers define macros that break Eigen's (pulled in above).
#include <httplib.h>

namespace {

using namespace std::chrono_literals;
using nlohmann::json;
namespace dds = rigger::dds;

struct Leaf {
  std::string id, parent, name;
};

/// A valid recipe of exactly `n` nodes: a Sequence of Sequences of (up to) 100 Localize leaves. Its
/// leaves (node ids as the controller names them, "root/g/i") go to `leaves`.
json recipe_of(const std::string& task_id, int n, std::vector<Leaf>* leaves) {
  json groups = json::array();
  int left = n - 1, made = 0;
  while (left > 0) {
    const int size = left == 1 ? 0 : std::min(left - 1, 100);
    const std::string group_id = "root/" + std::to_string(groups.size());
    json children = json::array();
    for (int i = 0; i < size; ++i, ++made) {
      const std::string name = "localize " + std::to_string(made);
      children.push_back({{"type", "Skill"}, {"skill", "Localize"}, {"name", name},
                          {"params", {{"object", made % 2 ? "load" : "target"}}}});
      if (leaves) leaves->push_back({group_id + "/" + std::to_string(i), group_id, name});
    }
    if (size == 0) {  // one node left: a leaf of its own under the root
      const std::string name = "localize " + std::to_string(made++);
      groups.push_back({{"type", "Skill"}, {"skill", "Localize"}, {"name", name}, {"params", {{"object", "load"}}}});
      if (leaves) leaves->push_back({group_id, "root", name});
      break;
    }
    groups.push_back({{"type", "Sequence"}, {"name", "group " + std::to_string(groups.size())}, {"children", children}});
    left -= size + 1;
  }
  return {{"recipe_version", 1}, {"task_id", task_id}, {"root", {{"type", "Sequence"}, {"children", groups}}}};
}

std::string write_file(const std::string& path, const std::string& text) {
  std::ofstream(path) << text;
  return path;
}

/// The number k of a change ("bench change k") in an SSE frame, or -1.
long change_number(std::string_view event) {
  static constexpr std::string_view kTag = "\"message\":\"bench change ";
  const auto at = event.find(kTag);
  return at == std::string_view::npos ? -1 : std::atol(event.data() + at + kTag.size());
}

double wall_ms(std::chrono::system_clock::time_point t) {
  return std::chrono::duration<double, std::milli>(t.time_since_epoch()).count();
}

/// Saves the figures the browser script printed, the large tree's next to the 10-node one's and the
/// page's lag next to the reference client's (`sse_lag_ms`, `sse_max_ms`); 1 when a row is missing.
int save_figures(const std::string& browser_log, int nodes, int trials, int rate, int seconds,
                 const rigger::bench::Quantiles& sse_lag_ms, double sse_max_ms) {
  using rigger::bench::add_browser_row;
  rigger::performance::Report report(
      "bench_console_tree", "The console's Tasks page in headless chromium with a " + std::to_string(nodes) +
                                "-node tree (" + std::to_string(trials) + " clicks), next to a 10-node tree, then " +
                                std::to_string(rate) + " node changes per s for " + std::to_string(seconds) +
                                " s next to a browser-less SSE client");
  const std::vector<std::string> levels = {"p50", "p90", "p99", "max"};
  const auto rows = rigger::bench::browser_rows(browser_log);
  const std::string built = "click on the task -> whole tree drawn and laid out";
  const std::string painted = "click on the task -> the frame after it (painted)";
  const bool ok =
      add_browser_row(report, rows, levels, "page load -> Tasks page ready",
                      "page load -> Tasks page ready (the state of every node)", nodes + 10) &&
      add_browser_row(report, rows, levels, "click -> tree drawn", built, nodes, "10-node tree drawn", built, 10) &&
      add_browser_row(report, rows, levels, "click -> tree painted", painted, nodes, "10-node tree painted", painted,
                      10);
  const auto* dom =
      rigger::bench::browser_row(rows, "change stamped -> in the tree (DOM)", rigger::bench::kAnyCount, 4);
  const auto* frame = rigger::bench::browser_row(rows, "change stamped -> next frame began (painted by then)",
                                                 rigger::bench::kAnyCount, 4);
  if (!ok || !dom || !frame) return 1;
  // The reference client's lag was printed as p50, p99 and max.
  const std::pair<const char*, std::size_t> columns[] = {{"p50", 0}, {"p99", 2}, {"max", 3}};
  const double sse[] = {sse_lag_ms.p50, sse_lag_ms.p99, sse_max_ms};
  for (std::size_t i = 0; i < 3; ++i) {
    const std::string level = columns[i].first;
    report.add({"change -> in the tree (DOM) " + level, dom->ms[columns[i].second], "ms",
                "change -> SSE client " + level, sse[i]});
    report.add(
        {"change -> painted " + level, frame->ms[columns[i].second], "ms", "change -> SSE client " + level, sse[i]});
  }
  return rigger::performance::save_for_main(report);
}

}  // namespace

int main(int argc, char** argv) {
  using rigger::bench::int_option;
  const int nodes = int_option(argc, argv, "--nodes", 10000);
  const int trials = int_option(argc, argv, "--trials", 5);
  const int rate = int_option(argc, argv, "--rate", 1000);
  const int seconds = int_option(argc, argv, "--seconds", 10);
  const std::string repo = RIGGER_SOURCE_DIR;
  const std::string modules = rigger::bench::browser_modules();
  if (modules.empty()) return 2;

  rigger::testing::Cell cell;
  const std::string dir = cell.log_dir();
  cell.start("tc", "task_controller",
             {"--id", "tc", "--log-level", "warn", "--config",
              write_file(dir + "/tc.json", json{{"journal_path", dir + "/journal.sqlite"}}.dump())});
  cell.start("skills", "scripted_executor",
             {"--id", "skills", "--log-level", "warn", "--config",
              write_file(dir + "/skills.json",
                         json{{"skills", {"Localize"}}, {"default", {{"mode", "succeed"}, {"delay_s", 0}}}}.dump())});
  const auto console = rigger::bench::start_console(cell, {{"bench", rigger::console::Role::kViewer}});
  const auto& users = console.users;
  const std::uint16_t port = console.port;
  if (!cell.wait_ready({"tc", "skills", "console"}, 60s)) {
    std::fprintf(stderr, "the services did not become ready\n%s", cell.logs().c_str());
    return 1;
  }
  // The loop wakes every 50 ms, so that conditions on files and HTTP answers are looked at again.
  cell.loop().every(50ms, [] {});

  dds::Writer<rigger_task_Recipe> recipes(cell.participant(), rigger::protocol::task::kRecipe);
  dds::Reader<rigger_task_TaskStatus> statuses(cell.participant(), rigger::protocol::task::kStatus);
  dds::Writer<rigger_task_NodeStatus> changes(cell.participant(), rigger::protocol::task::kNodeStatus,
                                              dds::qos::state_changes());
  std::map<std::string, int> task_state;
  cell.loop().on_data(statuses, [&] {
    statuses.take([&](const rigger_task_TaskStatus& s, const dds_sample_info_t&) {
      task_state[dds::to_string(s.task_id)] = s.state;
    });
  });
  if (!recipes.wait_for_readers(1, 10s) || !changes.wait_for_readers(1, 10s)) {
    std::fprintf(stderr, "the controller's recipe reader or the console's node-status reader did not match\n");
    return 1;
  }
  httplib::Client http("127.0.0.1", port);
  http.set_read_timeout(30, 0);
  const httplib::Headers auth = {{"Authorization", "Bearer " + users[0].token}};

  // Both tasks run to the end; the console then holds every node's last status.
  const std::string small = "tree-10", large = "tree-" + std::to_string(nodes);
  std::vector<Leaf> leaves;
  for (const auto& [task, n] : {std::pair<std::string, int>{small, 10}, {large, nodes}}) {
    const auto t0 = std::chrono::steady_clock::now();
    rigger_task_Recipe r{};
    const std::string text = recipe_of(task, n, task == large ? &leaves : nullptr).dump(), submitter = "bench";
    r.task_id = dds::wire_string(task);
    r.recipe_json = dds::wire_string(text);
    r.submitter = dds::wire_string(submitter);
    r.stamp = dds::wire_now();
    recipes.write(r);
    if (!cell.wait_until([&] { return task_state[task] == rigger_task_TASK_SUCCEEDED; }, std::chrono::seconds(60 + n / 50))) {
      std::fprintf(stderr, "task %s did not succeed (state %d)\n%s", task.c_str(), task_state[task], cell.logs().c_str());
      return 1;
    }
    std::size_t known = 0;
    const bool all = cell.wait_until(
        [&] {
          const auto res = http.Get(("/api/state?task=" + task).c_str(), auth);
          if (!res || res->status != 200) return false;
          known = json::parse(res->body)["nodes"].value(task, json::array()).size();
          return known == static_cast<std::size_t>(n);
        },
        30s);
    if (!all) {
      std::fprintf(stderr, "the console knows %zu of the %d nodes of %s\n", known, n, task.c_str());
      return 1;
    }
    std::printf("%s: %d nodes run by the controller in %.1f s, all in the console\n", task.c_str(), n,
                std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
  }
  std::fflush(stdout);

  const int total = rate * seconds;
  bool done = false;
  rigger::testing::ChildProcess browser(
      "/usr/bin/node", {repo + "/test/bench/console/tree.mjs"},
      {{"CONSOLE_URL", "http://127.0.0.1:" + std::to_string(port)},
       {"TOKEN", users[0].token},
       {"TASKS", small + "," + large},
       {"TRIALS", std::to_string(trials)},
       {"CHANGES", std::to_string(total)},
       {"RATE", std::to_string(rate)},
       {"NODE_PATH", modules}},
      dir + "/browser.log", [&] { cell.loop().post([&] { done = true; }); });
  // The page says when it follows the large task.
  if (!cell.wait_until([&] { return done || browser.log().find("follow: ready") != std::string::npos; },
                       std::chrono::minutes(10)) ||
      done) {
    std::printf("%s", browser.log().c_str());
    std::fprintf(stderr, "the browser script ended before following the changes\n");
    return 1;
  }

  // The reference: the same changes as SSE events in a browser-less client (arrival, wall clock).
  std::vector<double> sse_ms(static_cast<std::size_t>(total), 0.0), stamp_ms(static_cast<std::size_t>(total), 0.0);
  std::atomic<int> received{0};
  std::atomic<bool> streaming{false};
  httplib::Client stream("127.0.0.1", port);
  stream.set_read_timeout(60, 0);
  std::thread reader([&] {
    std::string buffer;
    stream.Get(("/api/events?token=" + users[0].token).c_str(), httplib::Headers{}, [&](const httplib::Response&) {
      streaming = true;
      return true;
    }, [&](const char* data, std::size_t n) {
      rigger::bench::take_sse_events(buffer, data, n, [&](std::string_view event) {
        const long k = change_number(event);
        if (k < 0 || k >= total) return;
        sse_ms[static_cast<std::size_t>(k)] = wall_ms(std::chrono::system_clock::now());
        ++received;
      });
      return received < total;
    });
  });

  if (!cell.wait_until([&] { return streaming.load(); }, 10s)) {
    std::fprintf(stderr, "the reference SSE client got no answer\n");
    stream.stop();
    reader.join();
    return 1;
  }
  // Leaf j of a scattered order: a stride that shares no factor with the leaf count visits every leaf once.
  const auto nl = static_cast<long>(leaves.size());
  long stride = 97;
  while (std::gcd(stride, nl) != 1) ++stride;
  auto leaf_of = [&](long j) -> const Leaf& { return leaves[static_cast<std::size_t>((((j * stride) % nl) + nl) % nl)]; };
  const auto period = std::chrono::nanoseconds(1000000000LL / rate);
  const auto start = std::chrono::steady_clock::now() + 200ms;
  const std::string task = large, type = "Skill", executor = "skills";
  constexpr long kRunningChanges = 100;  // a leaf's SUCCESS comes this many changes after its RUNNING
  for (long k = 0; k < total; ++k) {
    std::this_thread::sleep_until(start + k * period);
    const bool starts = k % 2 == 0;
    // A SUCCESS names the change that started its leaf (when in this run): a page that draws once a
    // frame shows only the later of two changes of one node that came in the same frame.
    const long j = starts ? k / 2 : (k - 1) / 2 - kRunningChanges / 2;
    const Leaf& leaf = leaf_of(j);
    const std::string message =
        "bench change " + std::to_string(k) + (!starts && j >= 0 ? " after " + std::to_string(2 * j) : "");
    rigger_task_NodeStatus s{};
    s.task_id = dds::wire_string(task);
    s.node_id = dds::wire_string(leaf.id);
    s.parent_id = dds::wire_string(leaf.parent);
    s.node_type = dds::wire_string(type);
    s.name = dds::wire_string(leaf.name);
    s.state = starts ? rigger_task_NODE_RUNNING : rigger_task_NODE_SUCCESS;
    s.message = dds::wire_string(message);
    s.progress = -1;
    s.executor_id = dds::wire_string(executor);
    s.stamp = dds::wire_now();
    s.started = s.stamp;
    if (!starts) s.finished = s.stamp;
    stamp_ms[static_cast<std::size_t>(k)] = 1e3 * static_cast<double>(s.stamp.sec) + 1e-6 * s.stamp.nanosec;
    changes.write(s);
  }
  const double sent_over_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();

  const bool ended = cell.wait_until([&] { return done; }, std::chrono::minutes(3));
  stream.stop();
  reader.join();
  const auto exit = browser.wait(5s);
  std::printf("%s", browser.log().c_str());
  std::vector<double> lag;
  for (int k = 0; k < total; ++k)
    if (sse_ms[static_cast<std::size_t>(k)] > 0) lag.push_back(sse_ms[static_cast<std::size_t>(k)] - stamp_ms[static_cast<std::size_t>(k)]);
  using rigger::bench::percentile;
  std::printf("%d changes written in %.2f s (%.0f per s)\n", total, sent_over_s, total / sent_over_s);
  std::printf("reference: the same changes as SSE events in a browser-less client: %zu of %d, lag p50 %.1f ms, "
              "p99 %.1f ms, max %.1f ms\n",
              lag.size(), total, percentile(lag, 0.5), percentile(lag, 0.99), percentile(lag, 1.0));
  const auto report = cell.stop_all();
  if (!ended || !exit || !exit->ok()) {
    std::fprintf(stderr, "the browser script failed (log above)\n");
    return 1;
  }
  if (!report.ok) {
    std::fprintf(stderr, "%s", report.problems.c_str());
    return 1;
  }
  return save_figures(browser.log(), nodes, trials, rate, seconds, rigger::bench::quantiles(lag), percentile(lag, 1.0));
}
