// riggerctl tree: the last status of every node of a task, in pre-order.
#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <map>
#include <set>
#include <utility>
#include <vector>

#include "rigger/base/time.hpp"
#include "rigger/dds/conversions.hpp"
#include "task_support.hpp"

namespace rigger::ctl::tasks {

int show_tree(const CommonOptions& common, const std::string& task_id, double timeout_s) {
  dds::Participant participant(common.domain);
  dds::Reader<rigger_task_NodeStatus> nodes(participant, protocol::task::kNodeStatus);
  JournalTopics topics(participant);
  dds::EventLoop loop(participant);
  // Node status is transient-local, but it arrives some time after the reader matched (Cyclone's
  // wait_for_historical_data does not wait for transient-local data). The journal says which nodes
  // ever changed state, i.e. which statuses to wait for.
  const JournalAnswer journal = ask_journal(topics, loop, task_id, timeout_s);
  if (const int failed = journal_failure(journal, common, timeout_s, "no node status for task " + task_id))
    return failed;
  std::set<std::string> expected;
  for (const auto& l : journal.lines)
    if (l.kind == "NODE" && !l.node_id.empty()) expected.insert(l.node_id);
  std::map<std::string, NodeLine> tree;
  const auto have_all = [&] {
    return std::all_of(expected.begin(), expected.end(), [&](const std::string& id) { return tree.count(id) > 0; });
  };
  loop.on_data(nodes, [&] {
    nodes.take([&](const rigger_task_NodeStatus& s, const dds_sample_info_t&) {
      if (dds::to_string(s.task_id) == task_id) tree[dds::to_string(s.node_id)] = to_line(s);
    });
  });
  const bool complete = loop.run_until(have_all, from_seconds(timeout_s));
  if (tree.empty()) {
    std::fprintf(stderr, "riggerctl: no node status for task %s\n", task_id.c_str());
    return kExitFailed;
  }
  // Pre-order: ids compare by their numeric path ("root/2" before "root/10").
  std::vector<std::pair<std::vector<long>, std::string>> order;
  for (const auto& [id, n] : tree) {
    std::vector<long> path;
    for (std::size_t slash = id.find('/'); slash != std::string::npos; slash = id.find('/', slash + 1))
      path.push_back(std::strtol(id.c_str() + slash + 1, nullptr, 10));
    order.emplace_back(std::move(path), id);
  }
  std::sort(order.begin(), order.end());
  for (const auto& [path, id] : order) std::printf("%s\n", node_line(id, tree.at(id)).c_str());
  if (!complete)
    std::fprintf(stderr, "riggerctl: %zu of %zu nodes have no status (the controller restarted since?)\n",
                 expected.size() - std::min(expected.size(), tree.size()), expected.size());
  return 0;
}

}  // namespace rigger::ctl::tasks
