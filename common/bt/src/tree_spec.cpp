#include "rigger/bt/tree_spec.hpp"

#include <array>
#include <unordered_set>
#include <utility>

namespace rigger::bt {
namespace {

constexpr std::array<std::pair<NodeKind, std::string_view>, 12> kKindNames{{
    {NodeKind::kSequence, "Sequence"},
    {NodeKind::kFallback, "Fallback"},
    {NodeKind::kParallel, "Parallel"},
    {NodeKind::kSkill, "Skill"},
    {NodeKind::kMonitor, "Monitor"},
    {NodeKind::kCondition, "Condition"},
    {NodeKind::kInverter, "Inverter"},
    {NodeKind::kRetry, "Retry"},
    {NodeKind::kRepeat, "Repeat"},
    {NodeKind::kTimeout, "Timeout"},
    {NodeKind::kForceSuccess, "ForceSuccess"},
    {NodeKind::kOperatorDecision, "OperatorDecision"},
}};

// Durations become steady_clock deadlines; bound them far from overflow (and from NaN).
constexpr double kMaxDurationS = 1e7;

bool valid_duration(Seconds d) { return d.count() > 0.0 && d.count() <= kMaxDurationS; }

std::string where(const NodeSpec& node, NodeIndex index) {
  return "node " + (node.id.empty() ? "#" + std::to_string(index) : "\"" + node.id + "\"") + " (" +
         std::string(to_string(node.kind)) + ")";
}

}  // namespace

std::string_view to_string(NodeKind kind) {
  for (const auto& [k, name] : kKindNames) {
    if (k == kind) {
      return name;
    }
  }
  return "Unknown";
}

std::optional<NodeKind> node_kind_from_string(std::string_view name) {
  for (const auto& [k, n] : kKindNames) {
    if (n == name) {
      return k;
    }
  }
  return std::nullopt;
}

bool is_remote_leaf(NodeKind kind) { return kind == NodeKind::kSkill || kind == NodeKind::kMonitor; }

bool is_leaf(NodeKind kind) { return is_remote_leaf(kind) || kind == NodeKind::kCondition; }

bool is_decorator(NodeKind kind) {
  return kind == NodeKind::kInverter || kind == NodeKind::kRetry || kind == NodeKind::kRepeat ||
         kind == NodeKind::kTimeout || kind == NodeKind::kForceSuccess;
}

std::vector<std::optional<NodeIndex>> compute_parents(const TreeSpec& spec) {
  const std::size_t n = spec.nodes.size();
  if (n == 0 || spec.root >= n) {
    throw SpecError("tree has no root node (root index " + std::to_string(spec.root) + ", " + std::to_string(n) +
                    " nodes)");
  }
  std::vector<std::optional<NodeIndex>> parents(n);
  std::vector<bool> seen(n, false);
  seen[spec.root] = true;
  // Iterative walk: trees may be deep and this runs on untrusted shapes in tests.
  std::vector<NodeIndex> stack{spec.root};
  std::size_t visited = 1;
  while (!stack.empty()) {
    const NodeIndex index = stack.back();
    stack.pop_back();
    for (const NodeIndex child : spec.nodes[index].children) {
      if (child >= n) {
        throw SpecError(where(spec.nodes[index], index) + " has child index " + std::to_string(child) +
                        " out of range");
      }
      if (seen[child]) {
        throw SpecError(where(spec.nodes[child], child) + " is reached twice: the nodes do not form a tree");
      }
      seen[child] = true;
      parents[child] = index;
      ++visited;
      stack.push_back(child);
    }
  }
  if (visited != n) {
    for (NodeIndex i = 0; i < n; ++i) {
      if (!seen[i]) {
        throw SpecError(where(spec.nodes[i], i) + " is not reachable from the root");
      }
    }
  }
  return parents;
}

std::vector<bool> compute_can_succeed(const TreeSpec& spec) {
  const std::size_t n = spec.nodes.size();
  std::vector<bool> can(n, false);
  // Post-order without recursion: children before parents.
  std::vector<std::pair<NodeIndex, bool>> stack;
  if (spec.root < n) {
    stack.emplace_back(spec.root, false);
  }
  while (!stack.empty()) {
    auto [index, expanded] = stack.back();
    stack.pop_back();
    const NodeSpec& node = spec.nodes[index];
    if (!expanded) {
      stack.emplace_back(index, true);
      for (const NodeIndex child : node.children) {
        if (child < n) {
          stack.emplace_back(child, false);
        }
      }
      continue;
    }
    std::size_t able = 0;
    for (const NodeIndex child : node.children) {
      able += (child < n && can[child]) ? 1 : 0;
    }
    switch (node.kind) {
      case NodeKind::kSkill:
      case NodeKind::kCondition:
      case NodeKind::kInverter:
      case NodeKind::kForceSuccess:
        can[index] = true;
        break;
      case NodeKind::kMonitor:
        can[index] = false;
        break;
      case NodeKind::kSequence:
        can[index] = !node.children.empty() && able == node.children.size();
        break;
      case NodeKind::kFallback:
      case NodeKind::kOperatorDecision:
      case NodeKind::kRetry:
      case NodeKind::kRepeat:
      case NodeKind::kTimeout:
        can[index] = able > 0;
        break;
      case NodeKind::kParallel:
        can[index] = node.success_threshold >= 1 && able >= node.success_threshold;
        break;
    }
  }
  return can;
}

void check_tree_spec(const TreeSpec& spec) {
  (void)compute_parents(spec);
  // The engine starts and reports along tree paths recursively; recipes are far shallower
  // (their JSON depth is bounded), this bound only keeps trees built in code honest.
  std::vector<std::pair<NodeIndex, std::size_t>> walk{{spec.root, 1}};
  while (!walk.empty()) {
    const auto [index, depth] = walk.back();
    walk.pop_back();
    if (depth > kMaxTreeDepth) {
      throw SpecError(where(spec.nodes[index], index) + ": tree deeper than " + std::to_string(kMaxTreeDepth) +
                      " levels");
    }
    for (const NodeIndex child : spec.nodes[index].children) {
      walk.emplace_back(child, depth + 1);
    }
  }
  const auto can = compute_can_succeed(spec);
  std::unordered_set<std::string_view> ids;
  for (NodeIndex i = 0; i < spec.nodes.size(); ++i) {
    const NodeSpec& node = spec.nodes[i];
    const std::string at = where(node, i);
    if (node.id.empty()) {
      throw SpecError(at + " has an empty id");
    }
    if (!ids.insert(node.id).second) {
      throw SpecError(at + ": duplicate node id");
    }
    const std::size_t children = node.children.size();
    if (is_leaf(node.kind) && children != 0) {
      throw SpecError(at + ": a leaf has no children");
    }
    if (is_decorator(node.kind) && children != 1) {
      throw SpecError(at + ": a decorator has exactly one child, got " + std::to_string(children));
    }
    if (!is_leaf(node.kind) && !is_decorator(node.kind) && children == 0) {
      throw SpecError(at + ": needs at least one child");
    }
    if (is_leaf(node.kind) && node.leaf.empty()) {
      throw SpecError(at + ": leaf names no skill, monitor or condition");
    }
    if (is_remote_leaf(node.kind) && !valid_duration(node.stop_timeout)) {
      throw SpecError(at + ": stop timeout must be positive and at most 1e7 s");
    }
    switch (node.kind) {
      case NodeKind::kParallel: {
        std::size_t able = 0;
        for (const NodeIndex child : node.children) {
          able += can[child] ? 1 : 0;
        }
        if (node.success_threshold < 1 || node.success_threshold > able) {
          throw SpecError(at + ": success threshold " + std::to_string(node.success_threshold) +
                          " infeasible, expected 1.." + std::to_string(able) +
                          " (children that can succeed; monitors cannot)");
        }
        if (node.failure_threshold < 1 || node.failure_threshold > children) {
          throw SpecError(at + ": failure threshold " + std::to_string(node.failure_threshold) +
                          " infeasible, expected 1.." + std::to_string(children));
        }
        break;
      }
      case NodeKind::kRetry:
      case NodeKind::kRepeat:
        if (node.count < 1) {
          throw SpecError(at + ": count must be at least 1");
        }
        break;
      case NodeKind::kTimeout:
        if (!valid_duration(node.duration)) {
          throw SpecError(at + ": duration must be positive and at most 1e7 s");
        }
        break;
      case NodeKind::kOperatorDecision:
        if (node.options.size() != children) {
          throw SpecError(at + ": " + std::to_string(node.options.size()) + " options but " +
                          std::to_string(children) + " children");
        }
        break;
      default:
        break;
    }
  }
}

}  // namespace rigger::bt
