#include "task_support.hpp"

#include <algorithm>
#include <cstdio>
#include <ctime>

#include "rigger/dds/conversions.hpp"
#include "rigger/protocol/task_names.hpp"

namespace rigger::ctl::tasks {

using protocol::task::is_node_state;
using protocol::task::node_state_name;

bool task_terminal(int s) {
  return s == rigger_task_TASK_REJECTED || s == rigger_task_TASK_SUCCEEDED || s == rigger_task_TASK_FAILED ||
         s == rigger_task_TASK_CANCELED;
}

std::int64_t wire_ns(const rigger_geometry_Time& t) { return static_cast<std::int64_t>(t.sec) * 1000000000LL + t.nanosec; }

std::string format_wall(const rigger_geometry_Time& t) {
  const std::time_t secs = static_cast<std::time_t>(t.sec);
  std::tm tm{};
  gmtime_r(&secs, &tm);
  char buf[64];
  std::snprintf(buf, sizeof buf, "%02d:%02d:%02d.%03u", tm.tm_hour, tm.tm_min, tm.tm_sec, t.nanosec / 1000000U);
  return buf;
}

std::string node_line(const std::string& id, const NodeLine& n) {
  const auto depth = static_cast<std::size_t>(std::count(id.begin(), id.end(), '/'));
  std::string out(2 * depth, ' ');
  out += id + " " + n.type;
  if (!n.name.empty()) out += " \"" + n.name + "\"";
  out += "  " + n.state;
  // A finished node's progress is history.
  if (n.progress >= 0 &&
      (is_node_state(n.state, rigger_task_NODE_RUNNING) || is_node_state(n.state, rigger_task_NODE_STOPPING))) {
    char buf[32];
    std::snprintf(buf, sizeof buf, " %3.0f%%", n.progress * 100.0);
    out += buf;
  }
  if (!n.executor.empty()) out += "  @" + n.executor;
  if (!n.code.empty()) out += "  " + n.code;
  if (!n.message.empty()) out += ": " + n.message;
  return out;
}

NodeLine to_line(const rigger_task_NodeStatus& s) {
  return {dds::to_string(s.node_type), dds::to_string(s.name), node_state_name(s.state), dds::to_string(s.code),
          dds::to_string(s.message), dds::to_string(s.executor_id), s.progress};
}

}  // namespace rigger::ctl::tasks
