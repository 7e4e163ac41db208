// riggerctl run: submits a recipe and shows the live tree until the task ends.
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

#include "rigger/base/bounded_json.hpp"
#include "rigger/base/time.hpp"
#include "rigger/dds/conversions.hpp"
#include "rigger/dds/sequences.hpp"
#include "rigger/protocol/task_names.hpp"
#include "rigger/recipe/recipe_validator.hpp"
#include "run_display.hpp"
#include "task_support.hpp"

namespace rigger::ctl::tasks {
namespace {

using protocol::task::node_state_name;
using protocol::task::task_state_name;

NodeUpdate to_update(const rigger_task_NodeStatus& s) {
  NodeUpdate u;
  u.id = dds::to_string(s.node_id);
  u.type = dds::to_string(s.node_type);
  u.name = dds::to_string(s.name);
  u.state = node_state_name(s.state);
  u.code = dds::to_string(s.code);
  u.message = dds::to_string(s.message);
  u.executor = dds::to_string(s.executor_id);
  u.progress_text = dds::to_string(s.progress_text);
  u.progress = s.progress;
  u.started_s = static_cast<double>(wire_ns(s.started)) * 1e-9;
  u.finished_s = static_cast<double>(wire_ns(s.finished)) * 1e-9;
  return u;
}

std::string read_file(const std::string& path, std::string& error) {
  std::ifstream in(path, std::ios::binary);
  if (!in) {
    error = "cannot open " + path;
    return {};
  }
  std::ostringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

}  // namespace

int run_recipe(const CommonOptions& common, const RunOptions& opt) {
  std::string error;
  std::string text = opt.recipe_text.empty() ? read_file(opt.file, error) : opt.recipe_text;
  if (!error.empty()) {
    std::fprintf(stderr, "riggerctl: %s\n", error.c_str());
    return 2;
  }
  if (text.size() > recipe::kMaxRecipeBytesCeiling) {
    std::fprintf(stderr,
                 "riggerctl: %s: %.1f MB is more than any task controller accepts (max_recipe_bytes is at most "
                 "%zu MB, 4 MB by default); nothing was sent\n",
                 opt.file.c_str(), static_cast<double>(text.size()) / (1024.0 * 1024.0),
                 recipe::kMaxRecipeBytesCeiling / (1024U * 1024U));
    return kExitFailed;
  }
  std::string task_id = opt.task_id;
  {
    // Bounded like the controller's own parse; a bad file goes on unchanged, for the controller's validator to explain.
    auto parsed = parse_json_bounded(text, JsonLimits{recipe::kMaxRecipeBytesCeiling, recipe::Limits{}.max_depth});
    auto& doc = parsed.value;
    if (parsed.ok() && doc.is_object()) {
      if (!task_id.empty()) {
        doc["task_id"] = task_id;  // a new id for a re-run of the same file
        text = doc.dump(2);
      } else if (doc.contains("task_id") && doc["task_id"].is_string()) {
        task_id = doc["task_id"].get<std::string>();
      }
    }
  }
  if (task_id.empty()) task_id = std::filesystem::path(opt.file).stem().string();

  dds::Participant participant(common.domain);
  dds::EventLoop loop(participant);
  dds::Writer<rigger_task_Recipe> recipes(participant, protocol::task::kRecipe);
  dds::Reader<rigger_task_TaskStatus> statuses(participant, protocol::task::kStatus);
  dds::Reader<rigger_task_NodeStatus> nodes(participant, protocol::task::kNodeStatus, dds::qos::state_changes());

  // Also wait for the controller's status writers: a state change published before they matched
  // would reach us only as the latest state (state QoS keeps one sample per node), not as a line.
  const auto matched = [&](auto& reader) {
    return reader.wait_for_writers(1, from_seconds(opt.match_timeout_s));
  };
  if (!recipes.wait_for_readers(1, from_seconds(opt.match_timeout_s)) || !matched(statuses) || !matched(nodes)) {
    std::fprintf(stderr, "riggerctl: no task controller on %s (waited %.1f s)\n",
                 dds::describe_domain(common.domain).c_str(), opt.match_timeout_s);
    return kExitNoController;
  }
  const std::int64_t sent_ns = to_unix_ns(std::chrono::system_clock::now());
  std::map<std::string, NodeLine> tree;
  RunDisplay display(!opt.quiet && ::isatty(STDOUT_FILENO) != 0);
  bool finished = false;
  int final_state = -1;
  std::string code, message, failed_node;
  std::vector<std::pair<std::string, std::string>> errors;

  loop.on_data(nodes, [&] {
    // A take returns samples grouped by node (instance), not in the order they were written: the
    // controller writes a burst of changes together (a child's result, then its parent's). Shown in
    // the order of their stamps, they read as they happened.
    struct Change {
      std::int64_t stamp_ns;
      std::string id;
      NodeLine line;
      NodeUpdate update;
    };
    std::vector<Change> changes;
    nodes.take([&](const rigger_task_NodeStatus& s, const dds_sample_info_t&) {
      if (dds::to_string(s.task_id) != task_id || wire_ns(s.stamp) < sent_ns) return;
      changes.push_back({wire_ns(s.stamp), dds::to_string(s.node_id), to_line(s), to_update(s)});
    });
    std::stable_sort(changes.begin(), changes.end(),
                     [](const Change& a, const Change& b) { return a.stamp_ns < b.stamp_ns; });
    for (auto& c : changes) {
      tree[c.id] = std::move(c.line);
      const std::string shown = display.update(c.update);
      if (!opt.quiet) std::fputs(shown.c_str(), stdout);
    }
    std::fflush(stdout);
  });
  loop.on_data(statuses, [&] {
    statuses.take([&](const rigger_task_TaskStatus& s, const dds_sample_info_t&) {
      // Transient-local: an old status of the same id may arrive first; only ours counts.
      if (dds::to_string(s.task_id) != task_id || wire_ns(s.stamp) < sent_ns) return;
      if (!task_terminal(s.state)) {  // the end is reported below, once
        std::printf("task %s %s\n", task_id.c_str(), task_state_name(s.state));
        std::fflush(stdout);
        return;
      }
      finished = true;
      final_state = s.state;
      code = dds::to_string(s.code);
      message = dds::to_string(s.message);
      failed_node = dds::to_string(s.failed_node);
      for (const auto& e : dds::elements(s.errors))
        errors.emplace_back(dds::to_string(e.pointer), dds::to_string(e.message));
    });
  });

  rigger_task_Recipe r{};
  const std::string submitter = "riggerctl";
  r.task_id = dds::wire_string(task_id);
  r.recipe_json = dds::wire_string(text);
  r.submitter = dds::wire_string(submitter);
  r.stamp = dds::wire_now();
  if (const dds_return_t rc = recipes.write(r); rc != DDS_RETCODE_OK) {
    std::fprintf(stderr, "riggerctl: publishing the recipe (%.1f MB) failed: %s%s\n",
                 static_cast<double>(text.size()) / (1024.0 * 1024.0), dds_strretcode(rc),
                 rc == DDS_RETCODE_TIMEOUT ? " (the controller did not take it in time)" : "");
    return kExitFailed;
  }
  const auto limit = opt.timeout_s > 0 ? from_seconds(opt.timeout_s) : from_seconds(365.0 * 24 * 3600);
  if (!loop.run_until([&] { return finished; }, limit)) {
    std::fprintf(stderr, "riggerctl: task %s did not finish within %.1f s (it keeps running; riggerctl cancel %s)\n",
                 task_id.c_str(), opt.timeout_s, task_id.c_str());
    return kExitFailed;
  }
  const double wall_s = static_cast<double>(to_unix_ns(std::chrono::system_clock::now()) - sent_ns) * 1e-9;
  if (!opt.quiet && display.skills_run() > 0) std::printf("%s", display.durations(wall_s).c_str());
  if (final_state == rigger_task_TASK_SUCCEEDED) {
    std::printf("task %s SUCCEEDED\n", task_id.c_str());
    return 0;
  }
  std::fprintf(stderr, "task %s %s", task_id.c_str(), task_state_name(final_state));
  if (!failed_node.empty()) {
    auto it = tree.find(failed_node);
    std::fprintf(stderr, " at %s", failed_node.c_str());
    if (it != tree.end() && !it->second.name.empty()) std::fprintf(stderr, " (%s)", it->second.name.c_str());
  }
  std::fprintf(stderr, ": %s %s\n", code.c_str(), message.c_str());
  for (const auto& [pointer, msg] : errors) std::fprintf(stderr, "  %s: %s\n", pointer.c_str(), msg.c_str());
  return kExitFailed;
}

}  // namespace rigger::ctl::tasks
