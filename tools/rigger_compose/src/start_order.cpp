#include "rigger/compose/start_order.hpp"

#include <algorithm>
#include <map>
#include <set>

namespace rigger::compose {
namespace {

std::string join_cycle(const std::vector<std::string>& cycle) {
  std::string out;
  for (const auto& name : cycle) out += (out.empty() ? "" : " -> ") + name;
  return out;
}

// Depth-first topological sort. Visiting services in file order and their dependencies in listed order
// keeps the result stable (independent services keep the file's order), which makes `up` predictable.
class Sorter {
 public:
  explicit Sorter(const std::vector<ServiceDeps>& graph) {
    for (const auto& node : graph) {
      if (!by_name_.emplace(node.name, &node).second)
        throw std::invalid_argument("service '" + node.name + "' is defined twice");
    }
    for (const auto& node : graph) {
      for (const auto& dep : node.depends_on) {
        if (!by_name_.count(dep))
          throw std::invalid_argument("service '" + node.name + "' depends on unknown service '" + dep + "'");
      }
    }
  }

  void visit(const std::string& name) {
    if (done_.count(name)) return;
    const auto on_path = std::find(path_.begin(), path_.end(), name);
    if (on_path != path_.end()) {
      std::vector<std::string> cycle(on_path, path_.end());
      cycle.push_back(name);
      throw DependencyCycleError(cycle);
    }
    path_.push_back(name);
    for (const auto& dep : by_name_.at(name)->depends_on) visit(dep);
    path_.pop_back();
    done_.insert(name);
    order_.push_back(name);
  }

  bool known(const std::string& name) const { return by_name_.count(name) > 0; }
  const std::vector<std::string>& order() const { return order_; }

 private:
  std::map<std::string, const ServiceDeps*> by_name_;
  std::vector<std::string> path_;
  std::set<std::string> done_;
  std::vector<std::string> order_;
};

}  // namespace

DependencyCycleError::DependencyCycleError(std::vector<std::string> cycle)
    : std::runtime_error("dependency cycle: " + join_cycle(cycle)), cycle_(std::move(cycle)) {}

std::vector<std::string> start_order(const std::vector<ServiceDeps>& graph) {
  Sorter sorter(graph);
  for (const auto& node : graph) sorter.visit(node.name);
  return sorter.order();
}

std::vector<std::string> with_dependencies(const std::vector<ServiceDeps>& graph,
                                           const std::vector<std::string>& selected) {
  const auto all = start_order(graph);  // also rejects cycles outside the selection: the file is wrong
  if (selected.empty()) return all;
  Sorter sorter(graph);
  for (const auto& name : selected) {
    if (!sorter.known(name)) throw std::invalid_argument("no service named '" + name + "'");
    sorter.visit(name);
  }
  // Reorder the closure by the global order so that `up a b` and `up b a` start alike.
  std::set<std::string> closure(sorter.order().begin(), sorter.order().end());
  std::vector<std::string> out;
  for (const auto& name : all)
    if (closure.count(name)) out.push_back(name);
  return out;
}

std::vector<std::string> dependants_of(const std::vector<ServiceDeps>& graph, const std::string& name) {
  std::vector<std::string> out;
  for (const auto& node : graph) {
    if (std::find(node.depends_on.begin(), node.depends_on.end(), name) != node.depends_on.end())
      out.push_back(node.name);
  }
  return out;
}

}  // namespace rigger::compose
