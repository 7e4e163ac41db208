#include "rigger/bt/tree_builder.hpp"

namespace rigger::bt::build {
namespace {

Node with_children(NodeKind kind, std::vector<Node> children) {
  Node n;
  n.kind = kind;
  n.children = std::move(children);
  return n;
}

Node leaf(NodeKind kind, std::string name, nlohmann::json params) {
  Node n;
  n.kind = kind;
  n.leaf = std::move(name);
  n.params = std::move(params);
  return n;
}

NodeIndex add(TreeSpec& spec, const Node& node, const std::string& id) {
  const NodeIndex index = spec.nodes.size();
  NodeSpec s;
  s.kind = node.kind;
  s.id = id;
  s.name = node.name;
  s.leaf = node.leaf;
  s.params = node.params;
  s.resources = node.resources;
  s.executor = node.executor;
  s.stop_timeout = Seconds(node.stop_timeout_s);
  s.success_threshold = node.success_threshold;
  s.failure_threshold = node.failure_threshold;
  s.count = node.count;
  s.duration = Seconds(node.duration_s);
  s.prompt = node.prompt;
  s.options = node.options;
  spec.nodes.push_back(std::move(s));
  for (std::size_t i = 0; i < node.children.size(); ++i) {
    const NodeIndex child = add(spec, node.children[i], id + "/" + std::to_string(i));
    spec.nodes[index].children.push_back(child);
  }
  return index;
}

}  // namespace

Node sequence(std::vector<Node> children) { return with_children(NodeKind::kSequence, std::move(children)); }
Node fallback(std::vector<Node> children) { return with_children(NodeKind::kFallback, std::move(children)); }

Node parallel(std::size_t success_threshold, std::size_t failure_threshold, std::vector<Node> children) {
  Node n = with_children(NodeKind::kParallel, std::move(children));
  n.success_threshold = success_threshold;
  n.failure_threshold = failure_threshold;
  return n;
}

Node skill(std::string name, std::vector<std::string> resources, nlohmann::json params) {
  Node n = leaf(NodeKind::kSkill, std::move(name), std::move(params));
  n.resources = std::move(resources);
  return n;
}

Node monitor(std::string name, nlohmann::json params) { return leaf(NodeKind::kMonitor, std::move(name), std::move(params)); }
Node condition(std::string name, nlohmann::json params) {
  return leaf(NodeKind::kCondition, std::move(name), std::move(params));
}

Node inverter(Node child) { return with_children(NodeKind::kInverter, {std::move(child)}); }
Node force_success(Node child) { return with_children(NodeKind::kForceSuccess, {std::move(child)}); }

Node retry(std::size_t max_attempts, Node child) {
  Node n = with_children(NodeKind::kRetry, {std::move(child)});
  n.count = max_attempts;
  return n;
}

Node repeat(std::size_t count, Node child) {
  Node n = with_children(NodeKind::kRepeat, {std::move(child)});
  n.count = count;
  return n;
}

Node timeout(double duration_s, Node child) {
  Node n = with_children(NodeKind::kTimeout, {std::move(child)});
  n.duration_s = duration_s;
  return n;
}

Node decision(std::string prompt, std::vector<std::pair<std::string, Node>> options) {
  Node n;
  n.kind = NodeKind::kOperatorDecision;
  n.prompt = std::move(prompt);
  for (auto& [label, child] : options) {
    n.options.push_back(label);
    n.children.push_back(std::move(child));
  }
  return n;
}

TreeSpec build(const Node& root) {
  TreeSpec spec;
  spec.root = add(spec, root, "root");
  return spec;
}

}  // namespace rigger::bt::build
