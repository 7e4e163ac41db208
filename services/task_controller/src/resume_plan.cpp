#include "resume_plan.hpp"

#include <map>
#include <optional>
#include <set>

namespace rigger::task_controller {
namespace {

using bt::NodeIndex;
using bt::NodeKind;
using bt::NodeState;
using bt::Restored;

std::optional<NodeState> state_from_string(const std::string& name) {
  for (const NodeState s : {NodeState::kIdle, NodeState::kRunning, NodeState::kStopping, NodeState::kSuccess,
                            NodeState::kFailure, NodeState::kStopped})
    if (bt::to_string(s) == name) return s;
  return std::nullopt;
}

/// A NODE row's message is "CODE: message" when the node had a code (Task::node_changed).
std::string code_of(const std::string& message) {
  const auto colon = message.find(": ");
  if (colon == std::string::npos || colon == 0) return "";
  for (std::size_t i = 0; i < colon; ++i) {
    const char c = message[i];
    if (!((c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '_')) return "";
  }
  return message.substr(0, colon);
}

/// What the timeline says about one node.
struct Seen {
  NodeState state = NodeState::kIdle;
  std::string message;
  bt::Activation activations = 0;     ///< times it entered RUNNING
  std::size_t cursor = 0;             ///< Retry: child failures; Repeat: child successes (this activation)
  std::optional<std::size_t> chosen;  ///< OperatorDecision: the option whose child entered RUNNING
};

bool active(NodeState s) {
  return s == NodeState::kRunning || s == NodeState::kStopping;
}

class Planner {
 public:
  Planner(const bt::TreeSpec& spec, ResumePlan& plan, const std::set<std::string>& again)
      : spec_(spec), plan_(plan), seen_(spec.nodes.size()) {
    for (NodeIndex i = 0; i < spec.nodes.size(); ++i) {
      index_[spec.nodes[i].id] = i;
      for (std::size_t c = 0; c < spec.nodes[i].children.size(); ++c) parent_[spec.nodes[i].children[c]] = {i, c};
    }
    for (const auto& id : again)
      if (const auto it = index_.find(id); it != index_.end() && bt::is_leaf(spec.nodes[it->second].kind))
        again_.insert(it->second);
    plan_.restoration.nodes.resize(spec.nodes.size());
  }

  bool read(const std::vector<JournalRecord>& timeline) {
    for (const auto& r : timeline) {
      if (r.kind != "NODE") continue;
      const auto it = index_.find(r.node_id);
      if (it == index_.end()) {
        plan_.error = "journal row names node \"" + r.node_id + "\", which the recipe's tree does not have";
        return false;
      }
      const auto state = state_from_string(r.code);
      if (!state) {
        plan_.error = "journal row of node \"" + r.node_id + "\" has no node state: \"" + r.code + "\"";
        return false;
      }
      saw(it->second, *state, r.message);
    }
    return true;
  }

  void plan() {
    const NodeIndex root = spec_.root;
    const NodeState s = seen_[root].state;
    if (s == NodeState::kStopping) {
      plan_.error = "the task was being shut down (canceled) when the controller stopped; it is not resumed";
      return;
    }
    if (s == NodeState::kSuccess || s == NodeState::kFailure || s == NodeState::kStopped) {
      plan_.error = "the tree had finished (" + std::string(bt::to_string(s)) +
                    ") before the controller stopped; only the task's row is missing";
      return;
    }
    // A leaf that runs again opens its done ancestors, up to the first one that was running; only a path
    // of successes can be opened (below a failure, the leaf would not be reached).
    for (const NodeIndex leaf : again_) {
      if (seen_[leaf].state != NodeState::kSuccess) continue;
      std::vector<NodeIndex> path;
      NodeIndex at = leaf;
      bool open = false;
      for (auto p = parent_.find(at); p != parent_.end(); p = parent_.find(at)) {
        at = p->second.first;
        if (seen_[at].state == NodeState::kRunning) {
          open = true;
          break;
        }
        if (seen_[at].state != NodeState::kSuccess) break;
        path.push_back(at);
      }
      if (!open) continue;
      runs_again_.insert(leaf);
      reopened_.insert(path.begin(), path.end());
    }
    visit(root, s == NodeState::kRunning);
  }

 private:
  void saw(NodeIndex i, NodeState state, const std::string& message) {
    Seen& n = seen_[i];
    if (state == NodeState::kRunning && !active(n.state)) {
      ++n.activations;
      n.cursor = 0;
      n.chosen.reset();
      if (const auto p = parent_.find(i); p != parent_.end()) {
        const bt::NodeSpec& parent = spec_.nodes[p->second.first];
        if (parent.kind == NodeKind::kOperatorDecision) seen_[p->second.first].chosen = p->second.second;
      }
    }
    if (const auto p = parent_.find(i); p != parent_.end()) {
      const NodeKind parent_kind = spec_.nodes[p->second.first].kind;
      if ((parent_kind == NodeKind::kRetry && state == NodeState::kFailure) ||
          (parent_kind == NodeKind::kRepeat && state == NodeState::kSuccess))
        ++seen_[p->second.first].cursor;
    }
    n.state = state;
    n.message = message;
  }

  /// `i`'s restoration; `started`: it was RUNNING at the crash (its parent too).
  void visit(NodeIndex i, bool started) {
    const bt::NodeSpec& node = spec_.nodes[i];
    bt::RestoredNode& r = plan_.restoration.nodes[i];
    const Seen& n = seen_[i];
    r.activations = n.activations;
    if (!started) {
      pending(i);
      return;
    }
    if (bt::is_leaf(node.kind)) {
      if (node.kind == NodeKind::kSkill && !node.restartable) {
        plan_.ask.push_back(node.id);
      } else {
        plan_.rerun.push_back(node.id);
      }
      return;
    }
    r.cursor = n.cursor;
    r.chosen = n.chosen;
    const std::size_t guards = node.kind == NodeKind::kSequence ? guarding_conditions(node) : 0;
    restore_children(node, guards);
  }

  /// A done control node that runs again because a leaf below it does (plan()): its children are taken
  /// up as they were, the path to that leaf opened further. A Repeat had counted the success it gives.
  void reopen(NodeIndex i) {
    const bt::NodeSpec& node = spec_.nodes[i];
    bt::RestoredNode& r = plan_.restoration.nodes[i];
    const Seen& n = seen_[i];
    r.activations = n.activations;
    r.cursor = node.kind == NodeKind::kRepeat && n.cursor > 0 ? n.cursor - 1 : n.cursor;
    r.chosen = n.chosen;
    restore_children(node, 0);
  }

  void restore_children(const bt::NodeSpec& node, std::size_t guards) {
    for (const NodeIndex c : node.children) {
      const Seen& child = seen_[c];
      bt::RestoredNode& cr = plan_.restoration.nodes[c];
      cr.activations = child.activations;
      switch (child.state) {
        case NodeState::kSuccess:
          if (runs_again_.count(c) != 0) {
            plan_.relocalize.push_back(spec_.nodes[c].id);  // the world changed under it: runs again
            break;
          }
          if (reopened_.count(c) != 0) {
            reopen(c);
            break;
          }
          if (guards > 0 && guarded_.count(c) != 0) {
            plan_.rerun.push_back(spec_.nodes[c].id);  // the guard of what runs next: asked again
            break;
          }
          cr.how = Restored::kSucceeded;
          cr.message = "done before the controller restarted";
          plan_.done.push_back(spec_.nodes[c].id);
          break;
        case NodeState::kFailure:
          cr.how = Restored::kFailed;
          cr.code = code_of(child.message);
          cr.message = "failed before the controller restarted: " + child.message;
          break;
        case NodeState::kStopped:
        case NodeState::kStopping:
          cr.how = Restored::kStopped;
          cr.code = code_of(child.message);
          cr.message = "stopped when the controller stopped (its executor stops every run of a lost controller)";
          break;
        case NodeState::kRunning:
          visit(c, true);
          break;
        case NodeState::kIdle:
          visit(c, false);
          break;
      }
    }
  }

  /// A running Sequence's Conditions that succeeded right before its first unfinished child (nothing
  /// but Conditions between them and it): they guard what runs next, so they are evaluated again
  /// against the world as it is now (a pose that aged while the controller was down fails them).
  /// Marks them in guarded_; returns how many.
  std::size_t guarding_conditions(const bt::NodeSpec& sequence) {
    std::size_t next = 0;
    while (next < sequence.children.size() && seen_[sequence.children[next]].state == NodeState::kSuccess) ++next;
    if (next == sequence.children.size()) return 0;
    std::size_t marked = 0;
    for (std::size_t j = next; j-- > 0;) {
      const NodeIndex c = sequence.children[j];
      if (spec_.nodes[c].kind != NodeKind::kCondition) break;
      guarded_.insert(c);
      ++marked;
    }
    return marked;
  }

  /// Leaves below `i` (not started yet) that may run when their parent reaches them.
  void pending(NodeIndex i) {
    std::vector<NodeIndex> stack{i};
    while (!stack.empty()) {
      const NodeIndex d = stack.back();
      stack.pop_back();
      const bt::NodeSpec& node = spec_.nodes[d];
      plan_.restoration.nodes[d].activations = seen_[d].activations;
      if (bt::is_leaf(node.kind)) plan_.pending.push_back(node.id);
      stack.insert(stack.end(), node.children.rbegin(), node.children.rend());
    }
  }

  const bt::TreeSpec& spec_;
  ResumePlan& plan_;
  std::vector<Seen> seen_;
  std::map<std::string, NodeIndex> index_;
  std::map<NodeIndex, std::pair<NodeIndex, std::size_t>> parent_;  ///< child → (parent, position)
  std::set<NodeIndex> guarded_;  ///< succeeded Conditions evaluated again (guarding_conditions)
  std::set<NodeIndex> again_;    ///< leaves asked to run again (plan_resume's `again`)
  std::set<NodeIndex> runs_again_;  ///< those of again_ that can: a path of successes below a running node
  std::set<NodeIndex> reopened_;    ///< done control nodes on those paths, taken up as running
};

std::string list(const std::vector<std::string>& ids, const bt::TreeSpec& spec) {
  std::string out;
  for (const auto& id : ids) out += (out.empty() ? "" : ", ") + describe_node(spec, id);
  return out.empty() ? "nothing" : out;
}

}  // namespace

ResumePlan plan_resume(const bt::TreeSpec& spec, const std::vector<JournalRecord>& timeline,
                       const std::set<std::string>& again) {
  ResumePlan plan;
  Planner planner(spec, plan, again);
  if (planner.read(timeline)) planner.plan();
  return plan;
}

void skip_interrupted(ResumePlan& plan, const bt::TreeSpec& spec, const std::string& by) {
  for (const auto& id : plan.ask) {
    for (NodeIndex i = 0; i < spec.nodes.size(); ++i) {
      if (spec.nodes[i].id != id) continue;
      auto& r = plan.restoration.nodes[i];
      r.how = Restored::kSucceeded;
      r.message = "interrupted by the controller's crash; taken as done by " + by;
      plan.done.push_back(id);
    }
  }
  plan.ask.clear();
}

std::string describe_node(const bt::TreeSpec& spec, const std::string& node_id) {
  for (const auto& n : spec.nodes) {
    if (n.id != node_id) continue;
    const std::string what = !n.name.empty() ? n.name : !n.leaf.empty() ? n.leaf : std::string(bt::to_string(n.kind));
    return n.id + " (" + what + ")";
  }
  return node_id;
}

std::string describe_plan(const ResumePlan& plan, const bt::TreeSpec& spec) {
  std::string out = "done, not run again: " + list(plan.done, spec);
  out += "\nruns again (interrupted restartable skills and monitors; conditions, evaluated anew): " +
         list(plan.rerun, spec);
  if (!plan.relocalize.empty())
    out += "\nre-localized (done, but the world changed while the controller was down; runs again): " +
           list(plan.relocalize, spec);
  if (!plan.ask.empty())
    out += "\ninterrupted, not restartable (the operator decides: rerun, skip = take as done, abort): " +
           list(plan.ask, spec);
  out += "\nthen, when reached: " + list(plan.pending, spec);
  return out;
}

}  // namespace rigger::task_controller
