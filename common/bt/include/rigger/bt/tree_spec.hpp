#pragma once
/// The static shape of a behaviour tree: what the validator produces from a recipe and what the
/// engine runs. Plain data, no behaviour; build it with the recipe validator or tree_builder.hpp.

#include <chrono>
#include <cstddef>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include <nlohmann/json.hpp>

namespace rigger::bt {

/// Index of a node in TreeSpec::nodes.
using NodeIndex = std::size_t;
/// Durations in seconds, as in recipes.
using Seconds = std::chrono::duration<double>;

/// Every node type a recipe may use (docs/behavior-tree.md).
enum class NodeKind {
  kSequence,          ///< children one after another; first failure fails; all succeed → success
  kFallback,          ///< children one after another; first success succeeds; all fail → failure
  kParallel,          ///< all children at once; success_threshold (M) / failure_threshold (K), typed counting
  kSkill,             ///< remote leaf that acts; SUCCESS or FAILURE
  kMonitor,           ///< remote leaf that watches; never succeeds
  kCondition,         ///< question to the world model, answered at once
  kInverter,          ///< success ↔ failure of its child
  kRetry,             ///< restarts its child after a failure, up to max_attempts runs in all
  kRepeat,            ///< restarts its child after a success until it succeeded `count` times
  kTimeout,           ///< fails with TIMEOUT (after shutting the child down) when the child runs longer than `duration`
  kForceSuccess,      ///< succeeds whatever its child's result
  kOperatorDecision,  ///< asks the operator to pick one of `options`; runs the matching child
};

/// "Sequence", "Fallback", … — the names recipes use.
std::string_view to_string(NodeKind kind);
/// Inverse of to_string(NodeKind).
std::optional<NodeKind> node_kind_from_string(std::string_view name);
/// Skill or Monitor: a leaf that runs on an executor.
bool is_remote_leaf(NodeKind kind);
/// Skill, Monitor or Condition.
bool is_leaf(NodeKind kind);
/// Inverter, Retry, Repeat, Timeout, ForceSuccess: exactly one child.
bool is_decorator(NodeKind kind);

/// One node. Which fields matter depends on `kind`; the rest keep their defaults.
struct NodeSpec {
  NodeKind kind = NodeKind::kSequence;
  /// Stable id, unique in the tree: "root" for the top node, parent id + "/" + child position
  /// below it ("root/0/2"); decorators' child is "/0", OperatorDecision option i's child is "/i".
  std::string id;
  /// JSON pointer of the node in the recipe ("/root/children/0"), "" when built in code.
  std::string pointer;
  /// Display name ("" when the recipe gave none).
  std::string name;

  /// Skill, Monitor, Condition: the name in the skill library.
  std::string leaf;
  /// Skill, Monitor, Condition: parameters, defaults filled in, quantities in SI units.
  nlohmann::json params = nlohmann::json::object();
  /// Skill, Monitor: executor id the leaf is pinned to, "" for any executor offering it.
  std::string executor;
  /// Skill: resources claimed while it runs (robot, crane, …, object ids). Used for safe-stop escalation.
  std::vector<std::string> resources;
  /// Skill, Monitor: how long the leaf may take to answer SHUTDOWN with STOPPED before the
  /// controller escalates a safe stop of its resources.
  Seconds stop_timeout{5.0};
  /// Skill: may be started again without asking the operator when a controller crash interrupted it
  /// and the task is resumed (the recipe's `restartable`, default false).
  bool restartable = false;

  /// Parallel: M, successes needed among children that can succeed (monitors cannot).
  std::size_t success_threshold = 1;
  /// Parallel: K, failures (of any child) that fail the Parallel.
  std::size_t failure_threshold = 1;
  /// Retry: runs in all (≥ 1). Repeat: successful runs needed (≥ 1).
  std::size_t count = 1;
  /// Timeout: the child's deadline, measured from the Timeout node's start.
  Seconds duration{0.0};
  /// OperatorDecision: the question shown to the operator.
  std::string prompt;
  /// OperatorDecision: option labels; option i runs children[i].
  std::vector<std::string> options;

  /// Children in order.
  std::vector<NodeIndex> children;
};

/// A whole tree: nodes[root] is the top node; the task's result is its result.
struct TreeSpec {
  std::vector<NodeSpec> nodes;
  NodeIndex root = 0;
};

/// Thrown at setup when a TreeSpec is not a well-formed tree (bad indices, wrong child counts,
/// infeasible thresholds, duplicate ids, non-positive durations).
class SpecError : public std::invalid_argument {
 public:
  using std::invalid_argument::invalid_argument;
};

/// Whether each node can ever report SUCCESS, by the typed counting of Parallel: a monitor never
/// succeeds; Sequence needs all children to be able to; Fallback/OperatorDecision any;
/// Parallel when M children can; Inverter and ForceSuccess always can (a failure becomes
/// success); Retry, Repeat and Timeout when their child can; Skill and Condition can.
/// Indexed like spec.nodes. Requires a structurally valid tree (children indices in range, acyclic).
std::vector<bool> compute_can_succeed(const TreeSpec& spec);

/// Parents of every node (std::nullopt for the root), or SpecError when the nodes do not form
/// one tree rooted at spec.root in which every node is reachable exactly once.
std::vector<std::optional<NodeIndex>> compute_parents(const TreeSpec& spec);

/// Deepest tree the engine accepts (a recipe's JSON depth bound keeps recipes far below it).
inline constexpr std::size_t kMaxTreeDepth = 1000;

/// Checks everything the engine relies on; throws SpecError naming the node id and the problem.
void check_tree_spec(const TreeSpec& spec);

}  // namespace rigger::bt
