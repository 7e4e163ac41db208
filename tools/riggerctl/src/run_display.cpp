#include "run_display.hpp"

#include <algorithm>
#include <cstdio>
#include <cstdlib>

#include "rigger/protocol/task_names.hpp"

namespace rigger::ctl {
namespace {

using protocol::task::is_node_state;

std::vector<std::string> split_id(const std::string& id) {
  std::vector<std::string> parts;
  std::size_t start = 0;
  while (true) {
    const std::size_t slash = id.find('/', start);
    parts.push_back(id.substr(start, slash == std::string::npos ? std::string::npos : slash - start));
    if (slash == std::string::npos) break;
    start = slash + 1;
  }
  return parts;
}

bool all_digits(const std::string& s) {
  return !s.empty() && std::all_of(s.begin(), s.end(), [](unsigned char c) { return c >= '0' && c <= '9'; });
}

// The node states by the names rigger/task/status gives them (task_names.hpp), never spelt here.
bool running(const std::string& state) {
  return is_node_state(state, rigger_task_NODE_RUNNING);
}
bool idle(const std::string& state) {
  return is_node_state(state, rigger_task_NODE_IDLE);
}
bool active_state(const std::string& state) {
  return running(state) || is_node_state(state, rigger_task_NODE_STOPPING);
}
bool finished_state(const std::string& state) {
  return is_node_state(state, rigger_task_NODE_SUCCESS) || is_node_state(state, rigger_task_NODE_FAILURE) ||
         is_node_state(state, rigger_task_NODE_STOPPED);
}

}  // namespace

bool tree_order_less(const std::string& a, const std::string& b) {
  const auto pa = split_id(a);
  const auto pb = split_id(b);
  for (std::size_t i = 0; i < std::min(pa.size(), pb.size()); ++i) {
    if (pa[i] == pb[i]) continue;
    if (all_digits(pa[i]) && all_digits(pb[i])) {
      if (pa[i].size() != pb[i].size()) return pa[i].size() < pb[i].size();
    }
    return pa[i] < pb[i];
  }
  return pa.size() < pb.size();
}

std::string RunDisplay::line(const NodeUpdate& n) {
  const auto depth = static_cast<std::size_t>(std::count(n.id.begin(), n.id.end(), '/'));
  std::string out(2 * depth, ' ');
  out += n.id + " " + n.type;
  if (!n.name.empty()) out += " \"" + n.name + "\"";
  out += "  " + n.state;
  if (n.progress >= 0) {
    char buf[32];
    std::snprintf(buf, sizeof buf, " %3.0f%%", n.progress * 100.0);
    out += buf;
  }
  if (!n.progress_text.empty() && running(n.state)) out += " (" + n.progress_text + ")";
  if (!n.executor.empty()) out += "  @" + n.executor;
  if (!n.code.empty()) out += "  " + n.code;
  if (!n.message.empty()) out += ": " + n.message;
  return out;
}

std::string RunDisplay::update(const NodeUpdate& node) {
  const NodeUpdate* before = nullptr;
  if (auto it = last_.find(node.id); it != last_.end()) before = &it->second;
  Timing& t = timing_[node.id];
  // A run begins when the node enters RUNNING (or is first seen already past it). Start times are not
  // compared: the controller converts them from its steady clock for every update, so they jitter.
  const bool active_before = before != nullptr && active_state(before->state);
  const bool seen_before = before != nullptr && !idle(before->state);
  const bool new_run = node.started_s > 0.0 && ((running(node.state) && !active_before) ||
                                                (!seen_before && !idle(node.state) && !running(node.state)));
  if (new_run) {
    if (t.runs == 0) t.first_started_s = node.started_s;
    t.last_started_s = node.started_s;
    ++t.runs;
  }
  if (node.finished_s > 0.0 && finished_state(node.state) && (before == nullptr || !finished_state(before->state))) {
    t.total_s += std::max(0.0, node.finished_s - node.started_s);
  }
  last_[node.id] = node;

  if (!redraw_) return line(node) + "\n";

  std::vector<const NodeUpdate*> shown;
  for (const auto& [id, n] : last_)
    if (!idle(n.state)) shown.push_back(&n);
  std::sort(shown.begin(), shown.end(),
            [](const NodeUpdate* a, const NodeUpdate* b) { return tree_order_less(a->id, b->id); });
  std::string out;
  if (drawn_lines_ > 0) out += "\x1b[" + std::to_string(drawn_lines_) + "F";  // to the first line drawn
  for (const NodeUpdate* n : shown) out += "\x1b[2K" + line(*n) + "\n";
  out += "\x1b[J";  // clear anything below (a shorter tree)
  drawn_lines_ = shown.size();
  return out;
}

std::size_t RunDisplay::skills_run() const {
  std::size_t n = 0;
  for (const auto& [id, node] : last_) {
    const auto it = timing_.find(id);
    if (node.type == "Skill" && it != timing_.end() && it->second.runs > 0) ++n;
  }
  return n;
}

std::string RunDisplay::durations(double wall_s) const {
  std::vector<std::pair<double, std::string>> skills;
  for (const auto& [id, n] : last_) {
    if (n.type != "Skill") continue;
    const auto it = timing_.find(id);
    if (it == timing_.end() || it->second.runs == 0) continue;
    const Timing& t = it->second;
    const double last_run = n.finished_s > 0.0 ? n.finished_s - n.started_s : 0.0;
    char buf[256];
    if (t.runs > 1) {
      std::snprintf(buf, sizeof buf, "  %-34s %-8s %7.1f s  (%d runs, %.1f s in all)%s%s",
                    (n.name.empty() ? id : n.name).c_str(), n.state.c_str(), last_run, t.runs, t.total_s,
                    n.code.empty() ? "" : "  ", n.code.c_str());
    } else {
      std::snprintf(buf, sizeof buf, "  %-34s %-8s %7.1f s%s%s", (n.name.empty() ? id : n.name).c_str(),
                    n.state.c_str(), last_run, n.code.empty() ? "" : "  ", n.code.c_str());
    }
    skills.emplace_back(t.first_started_s, buf);
  }
  std::stable_sort(skills.begin(), skills.end(),
                   [](const auto& a, const auto& b) { return a.first < b.first; });
  std::string out = "skill                                state       time\n";
  for (const auto& [start, text] : skills) out += text + "\n";
  char wall[96];
  std::snprintf(wall, sizeof wall, "wall time of the task: %.1f s\n", wall_s);
  return out + wall;
}

}  // namespace rigger::ctl
