#pragma once
/// @file
/// The order in which services start: every service after the services it depends on; among
/// independent services, the order of the file. Stopping uses the reverse.

#include <stdexcept>
#include <string>
#include <vector>

namespace rigger::compose {

/// One node of the dependency graph.
struct ServiceDeps {
  std::string name;
  std::vector<std::string> depends_on;
};

/// The graph has a cycle; `cycle()` lists it with the first service repeated at the end (a → b → a).
class DependencyCycleError : public std::runtime_error {
 public:
  explicit DependencyCycleError(std::vector<std::string> cycle);
  const std::vector<std::string>& cycle() const { return cycle_; }

 private:
  std::vector<std::string> cycle_;
};

/// Every service of `graph`, each after its dependencies, otherwise in the given order.
/// @throws DependencyCycleError; std::invalid_argument for a dependency that is not in `graph` or a
/// name given twice.
std::vector<std::string> start_order(const std::vector<ServiceDeps>& graph);

/// `selected` and everything they depend on (transitively), in start order. An empty `selected`
/// means every service. @throws like start_order, and std::invalid_argument for an unknown selected name.
std::vector<std::string> with_dependencies(const std::vector<ServiceDeps>& graph,
                                           const std::vector<std::string>& selected);

/// The services of `graph` that depend on `name` directly.
std::vector<std::string> dependants_of(const std::vector<ServiceDeps>& graph, const std::string& name);

}  // namespace rigger::compose
