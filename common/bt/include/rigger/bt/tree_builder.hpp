#pragma once
/// Building a TreeSpec in code — for tests, benchmarks and tools that do not start from a
/// recipe. Ids follow the recipe convention ("root", "root/0", "root/0/2"), nodes are stored in
/// pre-order (a node before its descendants). Recursion depth equals the tree depth.
///
///   using namespace rigger::bt::build;
///   TreeSpec tree = build(parallel(1, 1, {skill("AttachRobotToLoad"), monitor("YankMonitor")}));

#include <string>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

#include "rigger/bt/tree_spec.hpp"

namespace rigger::bt::build {

/// A node and its subtree, by value.
struct Node {
  NodeKind kind = NodeKind::kSequence;
  std::string leaf;
  nlohmann::json params = nlohmann::json::object();
  std::vector<std::string> resources;
  std::string executor;
  double stop_timeout_s = 1.0;
  std::size_t success_threshold = 1;
  std::size_t failure_threshold = 1;
  std::size_t count = 1;
  double duration_s = 0.0;
  std::string prompt;
  std::vector<std::string> options;
  std::string name;
  std::vector<Node> children;
};

Node sequence(std::vector<Node> children);
Node fallback(std::vector<Node> children);
Node parallel(std::size_t success_threshold, std::size_t failure_threshold, std::vector<Node> children);
Node skill(std::string name, std::vector<std::string> resources = {}, nlohmann::json params = nlohmann::json::object());
Node monitor(std::string name, nlohmann::json params = nlohmann::json::object());
Node condition(std::string name, nlohmann::json params = nlohmann::json::object());
Node inverter(Node child);
Node force_success(Node child);
Node retry(std::size_t max_attempts, Node child);
Node repeat(std::size_t count, Node child);
Node timeout(double duration_s, Node child);
Node decision(std::string prompt, std::vector<std::pair<std::string, Node>> options);

/// The TreeSpec of `root` (not checked; Engine's constructor checks it).
TreeSpec build(const Node& root);

}  // namespace rigger::bt::build
