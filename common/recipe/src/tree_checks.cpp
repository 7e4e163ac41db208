#include "tree_checks.hpp"

#include <algorithm>
#include <cctype>
#include <cstdint>
#include <map>
#include <optional>
#include <set>
#include <string>
#include <unordered_map>
#include <utility>

#include "rigger/skill/param_check.hpp"

namespace rigger::recipe::detail {
namespace {

using Json = nlohmann::json;
using bt::NodeIndex;
using bt::NodeKind;

std::size_t edit_distance(const std::string& a, const std::string& b) {
  std::vector<std::size_t> row(b.size() + 1);
  for (std::size_t j = 0; j <= b.size(); ++j) {
    row[j] = j;
  }
  for (std::size_t i = 1; i <= a.size(); ++i) {
    std::size_t diagonal = row[0];
    row[0] = i;
    for (std::size_t j = 1; j <= b.size(); ++j) {
      const std::size_t above = row[j];
      const bool same = std::tolower(static_cast<unsigned char>(a[i - 1])) ==
                        std::tolower(static_cast<unsigned char>(b[j - 1]));
      row[j] = std::min({row[j] + 1, row[j - 1] + 1, diagonal + (same ? 0 : 1)});
      diagonal = above;
    }
  }
  return row[b.size()];
}

std::string list_names(const std::vector<std::string>& names) {
  std::string out;
  for (std::size_t i = 0; i < names.size(); ++i) {
    out += (i == 0 ? "" : ", ") + names[i];
  }
  return out;
}

std::string describe_leaf(const bt::NodeSpec& node) {
  return std::string(bt::to_string(node.kind)) + " " + node.leaf + " at " + node.pointer;
}

class Builder {
 public:
  Builder(const skill::SkillLibrary& library, const Limits& limits, std::vector<Error>& errors,
          std::vector<ErrorCode>& codes, BuiltTree& out)
      : library_(library), limits_(limits), errors_(errors), codes_(codes), out_(out) {}

  std::optional<NodeIndex> add(const Json& j, const std::string& pointer, const std::string& id, bt::Seconds stop,
                               std::size_t depth) {
    if (out_.tree.nodes.size() >= limits_.max_nodes || depth > limits_.max_depth) {
      if (out_.complete) {
        errors_.push_back({pointer, out_.tree.nodes.size() >= limits_.max_nodes
                                        ? "recipe has more than " + std::to_string(limits_.max_nodes) +
                                              " nodes: expected at most " + std::to_string(limits_.max_nodes)
                                        : "tree deeper than " + std::to_string(limits_.max_depth) + " levels"});
      }
      out_.complete = false;
      return std::nullopt;
    }
    const NodeIndex index = out_.tree.nodes.size();
    out_.tree.nodes.emplace_back();
    out_.facts.emplace_back();
    const NodeKind kind = *bt::node_kind_from_string(j["type"].get<std::string>());
    {
      bt::NodeSpec& n = out_.tree.nodes[index];
      n.kind = kind;
      n.id = id;
      n.pointer = pointer;
      n.name = j.value("name", "");
    }
    if (j.contains("stop_timeout_s")) {
      stop = bt::Seconds(j["stop_timeout_s"].get<double>());
    }
    switch (kind) {
      case NodeKind::kSkill:
      case NodeKind::kMonitor:
      case NodeKind::kCondition:
        leaf(j, index, stop);
        break;
      case NodeKind::kSequence:
      case NodeKind::kFallback:
      case NodeKind::kParallel: {
        if (kind == NodeKind::kParallel) {
          out_.tree.nodes[index].success_threshold = j["success_threshold"].get<std::size_t>();
          out_.tree.nodes[index].failure_threshold = j["failure_threshold"].get<std::size_t>();
        }
        const Json& children = j["children"];
        for (std::size_t i = 0; i < children.size(); ++i) {
          const std::string suffix = std::to_string(i);
          if (const auto child = add(children[i], pointer + "/children/" + suffix, id + "/" + suffix, stop, depth + 1)) {
            out_.tree.nodes[index].children.push_back(*child);
          }
        }
        break;
      }
      case NodeKind::kInverter:
      case NodeKind::kForceSuccess:
      case NodeKind::kRetry:
      case NodeKind::kRepeat:
      case NodeKind::kTimeout: {
        if (kind == NodeKind::kRetry) {
          out_.tree.nodes[index].count = j["max_attempts"].get<std::size_t>();
        } else if (kind == NodeKind::kRepeat) {
          out_.tree.nodes[index].count = j["repetitions"].get<std::size_t>();
        } else if (kind == NodeKind::kTimeout) {
          out_.tree.nodes[index].duration = bt::Seconds(j["duration_s"].get<double>());
        }
        if (const auto child = add(j["child"], pointer + "/child", id + "/0", stop, depth + 1)) {
          out_.tree.nodes[index].children.push_back(*child);
        }
        break;
      }
      case NodeKind::kOperatorDecision: {
        out_.tree.nodes[index].prompt = j["prompt"].get<std::string>();
        const Json& options = j["options"];
        std::set<std::string> labels;
        for (std::size_t i = 0; i < options.size(); ++i) {
          const std::string suffix = std::to_string(i);
          const std::string option_pointer = pointer + "/options/" + suffix;
          const std::string label = options[i]["label"].get<std::string>();
          if (!labels.insert(label).second) {
            errors_.push_back({option_pointer + "/label", "duplicate option label \"" + label +
                                                               "\": the operator could not tell the options apart"});
          }
          out_.tree.nodes[index].options.push_back(label);
          if (const auto child = add(options[i]["child"], option_pointer + "/child", id + "/" + suffix, stop, depth + 1)) {
            out_.tree.nodes[index].children.push_back(*child);
          }
        }
        break;
      }
    }
    return index;
  }

 private:
  void leaf(const Json& j, NodeIndex index, bt::Seconds stop) {
    bt::NodeSpec& n = out_.tree.nodes[index];
    const skill::SkillKind expected = n.kind == NodeKind::kSkill     ? skill::SkillKind::kSkill
                                      : n.kind == NodeKind::kMonitor ? skill::SkillKind::kMonitor
                                                                     : skill::SkillKind::kCondition;
    const std::string field(skill::to_string(expected));
    n.leaf = j[field].get<std::string>();
    n.executor = j.value("executor", "");
    n.restartable = n.kind == NodeKind::kSkill && j.value("restartable", false);
    n.stop_timeout = stop;
    const Json params = j.contains("params") ? j["params"] : Json::object();
    n.params = params;
    const skill::SkillDescription* description = library_.find(n.leaf);
    if (description == nullptr) {
      codes_.resize(errors_.size(), ErrorCode::kInvalid);
      codes_.push_back(expected == skill::SkillKind::kSkill     ? ErrorCode::kUnknownSkill
                       : expected == skill::SkillKind::kMonitor ? ErrorCode::kUnknownMonitor
                                                                : ErrorCode::kUnknownCondition);
      errors_.push_back({n.pointer + "/" + field, unknown_name_message(field, n.leaf, expected)});
      out_.leaves_resolved = false;
      return;
    }
    if (description->kind != expected) {
      const std::string actual(skill::to_string(description->kind));
      std::string type = actual;
      type[0] = static_cast<char>(std::toupper(static_cast<unsigned char>(type[0])));
      errors_.push_back({n.pointer + "/" + field, "\"" + n.leaf + "\" is a " + actual + ", not a " + field +
                                                      ": expected {\"type\": \"" + type + "\", \"" + actual +
                                                      "\": \"" + n.leaf + "\"}"});
      out_.leaves_resolved = false;
      return;
    }
    auto checked = skill::check_params(*description, params, n.pointer + "/params");
    if (!checked.ok()) {
      errors_.insert(errors_.end(), checked.errors.begin(), checked.errors.end());
      out_.leaves_resolved = false;
      return;
    }
    n.params = std::move(checked.params);
    n.resources = skill::resolve_resources(*description, n.params);
    LeafFacts& facts = out_.facts[index];
    for (const auto& p : description->preconditions) {
      if (const auto fact = p.ground(n.params)) {
        facts.preconditions.push_back(*fact);
      }
    }
    for (const auto& p : description->postconditions) {
      if (const auto fact = p.ground(n.params)) {
        (p.negated ? facts.deleted : facts.added).push_back(*fact);
      }
    }
  }

  std::string unknown_name_message(const std::string& field, const std::string& name, skill::SkillKind kind) const {
    const auto known = library_.names(kind);
    std::string message = "unknown " + field + " \"" + name + "\"";
    std::string closest;
    std::size_t best = 3;  // suggest only near misses
    for (const auto& candidate : known) {
      const std::size_t d = edit_distance(name, candidate);
      if (d < best) {
        best = d;
        closest = candidate;
      }
    }
    if (!closest.empty()) {
      message += " (did you mean \"" + closest + "\"?)";
    }
    if (known.empty()) {
      return message + "; the skill library has no " + field + "s";
    }
    return message + "; expected one of the library's " + field + "s: " + list_names(known);
  }

  const skill::SkillLibrary& library_;
  const Limits& limits_;
  std::vector<Error>& errors_;
  std::vector<ErrorCode>& codes_;  ///< as long as errors_ after each unknown name (padded with kInvalid)
  BuiltTree& out_;
};

// Facts interned to dense ids so that the flow analysis copies bit sets, not string sets: a
// 10,000-node recipe carries thousands of facts through thousands of nodes.
using FactId = std::uint32_t;
using FactIds = std::vector<FactId>;  // sorted, unique

class FactBits {
 public:
  explicit FactBits(std::size_t facts = 0) : words_((facts + 63) / 64, 0) {}
  void set(FactId f) { words_[f / 64] |= bit(f); }
  void reset(FactId f) { words_[f / 64] &= ~bit(f); }
  bool test(FactId f) const { return (words_[f / 64] & bit(f)) != 0; }
  FactBits without(const FactIds& ids) const {
    FactBits out = *this;
    for (const FactId f : ids) {
      out.reset(f);
    }
    return out;
  }
  FactBits& operator&=(const FactBits& other) {
    for (std::size_t i = 0; i < words_.size(); ++i) {
      words_[i] &= other.words_[i];
    }
    return *this;
  }

 private:
  static std::uint64_t bit(FactId f) { return std::uint64_t{1} << (f % 64); }
  std::vector<std::uint64_t> words_;
};

bool contains(const FactIds& ids, FactId f) { return std::binary_search(ids.begin(), ids.end(), f); }

class FactFlow {
 public:
  FactFlow(const BuiltTree& built, const std::vector<skill::Fact>& initial, std::vector<Error>& errors)
      : nodes_(built.tree.nodes), errors_(errors), can_(bt::compute_can_succeed(built.tree)) {
    const std::size_t n = nodes_.size();
    pre_.resize(n);
    added_.resize(n);
    may_delete_.resize(n);
    for (NodeIndex i = 0; i < n; ++i) {
      for (const auto& f : built.facts[i].preconditions) {
        pre_[i].push_back(intern(f));
      }
      for (const auto& f : built.facts[i].added) {
        added_[i].push_back(intern(f));
        producers_[intern(f)].push_back(i);
      }
      for (const auto& f : built.facts[i].deleted) {
        may_delete_[i].push_back(intern(f));
      }
    }
    for (const auto& f : initial) {
      initial_ids_.push_back(intern(f));
    }
    // Facts possibly deleted anywhere in each subtree (by a leaf that ran, fully or partly).
    for (NodeIndex i = n; i-- > 0;) {  // pre-order reversed: children first
      FactIds& mine = may_delete_[i];
      for (const NodeIndex c : nodes_[i].children) {
        mine.insert(mine.end(), may_delete_[c].begin(), may_delete_[c].end());
      }
      std::sort(mine.begin(), mine.end());
      mine.erase(std::unique(mine.begin(), mine.end()), mine.end());
    }
  }

  void run_tree(NodeIndex root) {
    FactBits in(names_.size());
    for (const FactId f : initial_ids_) {
      in.set(f);
    }
    run(root, in);
  }

 private:
  FactId intern(const skill::Fact& fact) {
    const auto [it, inserted] = ids_.emplace(fact, static_cast<FactId>(names_.size()));
    if (inserted) {
      names_.push_back(fact);
    }
    return it->second;
  }

  // Facts certainly true when node `n` succeeds, given the facts `in` certainly true at its start.
  FactBits run(NodeIndex n, const FactBits& in) {
    const bt::NodeSpec& node = nodes_[n];
    switch (node.kind) {
      case NodeKind::kSkill:
      case NodeKind::kCondition:
      case NodeKind::kMonitor: {
        check_leaf(n, in);
        FactBits out = in.without(may_delete_[n]);
        for (const FactId f : added_[n]) {
          out.set(f);
        }
        return out;
      }
      case NodeKind::kSequence: {
        FactBits facts = in;
        for (const NodeIndex c : node.children) {
          facts = run(c, facts);
        }
        return facts;
      }
      case NodeKind::kFallback: {
        // Alternative i runs only after alternatives 0..i-1 failed, having maybe deleted facts;
        // after the Fallback only what every alternative establishes is certain.
        FactBits facts = in;
        std::optional<FactBits> out;
        for (const NodeIndex c : node.children) {
          FactBits child_out = run(c, facts);
          out ? (void)(*out &= child_out) : (void)(out = std::move(child_out));
          facts = facts.without(may_delete_[c]);
        }
        return out ? *out : in;
      }
      case NodeKind::kOperatorDecision: {
        std::optional<FactBits> out;
        for (const NodeIndex c : node.children) {
          FactBits child_out = run(c, in);
          out ? (void)(*out &= child_out) : (void)(out = std::move(child_out));
        }
        return out ? *out : in;
      }
      case NodeKind::kParallel:
        return run_parallel(n, in);
      case NodeKind::kInverter:
      case NodeKind::kForceSuccess:
        // Success says nothing about the child having succeeded.
        run(node.children.front(), in);
        return in.without(may_delete_[n]);
      case NodeKind::kRetry:
      case NodeKind::kRepeat: {
        // Later runs start after earlier ones that may have deleted facts; one pass with the
        // facts that survive any number of runs covers every run (the analysis is monotone).
        const NodeIndex c = node.children.front();
        return run(c, node.count > 1 ? in.without(may_delete_[c]) : in);
      }
      case NodeKind::kTimeout:
        return run(node.children.front(), in);
    }
    return in;
  }

  FactBits run_parallel(NodeIndex n, const FactBits& in) {
    const bt::NodeSpec& node = nodes_[n];
    // Siblings run concurrently: a sibling's postconditions do not count, and its deletions may
    // happen at any moment. A child may rely on a fact only if no *other* child may delete it.
    std::map<FactId, std::size_t> deleters;
    for (const NodeIndex c : node.children) {
      for (const FactId f : may_delete_[c]) {
        ++deleters[f];
      }
    }
    FactBits base = in.without(may_delete_[n]);  // facts no child may delete
    std::size_t able = 0;
    for (const NodeIndex c : node.children) {
      able += can_[c] ? 1 : 0;
    }
    // Only when every child that can succeed must succeed is each one's result certain.
    const bool all_able_succeed = node.success_threshold == able;
    FactBits out = base;
    for (const NodeIndex c : node.children) {
      FactBits child_in = base;
      for (const FactId f : may_delete_[c]) {
        if (deleters[f] == 1 && in.test(f)) {
          child_in.set(f);  // only this child deletes it: it holds at this child's start
        }
      }
      const FactBits child_out = run(c, child_in);
      if (all_able_succeed && can_[c]) {
        for (const FactId f : added_in_subtree(c)) {
          const std::size_t others = deleters.count(f) ? deleters[f] - (contains(may_delete_[c], f) ? 1 : 0) : 0;
          if (child_out.test(f) && others == 0) {
            out.set(f);
          }
        }
      }
    }
    return out;
  }

  // Facts some leaf in the subtree adds (candidates for a Parallel child's contribution).
  FactIds added_in_subtree(NodeIndex n) const {
    FactIds out;
    std::vector<NodeIndex> stack{n};
    while (!stack.empty()) {
      const NodeIndex i = stack.back();
      stack.pop_back();
      out.insert(out.end(), added_[i].begin(), added_[i].end());
      stack.insert(stack.end(), nodes_[i].children.begin(), nodes_[i].children.end());
    }
    std::sort(out.begin(), out.end());
    out.erase(std::unique(out.begin(), out.end()), out.end());
    return out;
  }

  void check_leaf(NodeIndex n, const FactBits& in) {
    const bt::NodeSpec& node = nodes_[n];
    for (const FactId p : pre_[n]) {
      if (in.test(p)) {
        continue;
      }
      std::string message = "precondition \"" + names_[p] + "\" of " + std::string(bt::to_string(node.kind)) + " " +
                            node.leaf + " may not hold when it starts: expected it among the initial facts or "
                            "assumptions, or established by a skill that certainly runs (and succeeds) before";
      const auto it = producers_.find(p);
      if (it != producers_.end()) {
        message += "; it is established by ";
        const std::size_t shown = std::min<std::size_t>(it->second.size(), 3);
        for (std::size_t i = 0; i < shown; ++i) {
          message += (i == 0 ? "" : ", ") + describe_leaf(nodes_[it->second[i]]);
        }
        message += ", which does not certainly run before it (alternative, concurrent, later, or possibly undone)";
      }
      errors_.push_back({node.pointer, message});
    }
  }

  const std::vector<bt::NodeSpec>& nodes_;
  std::vector<Error>& errors_;
  std::vector<bool> can_;
  std::unordered_map<skill::Fact, FactId> ids_;
  std::vector<skill::Fact> names_;
  std::vector<FactIds> pre_;
  std::vector<FactIds> added_;
  std::vector<FactIds> may_delete_;
  FactIds initial_ids_;
  std::map<FactId, std::vector<NodeIndex>> producers_;
};

}  // namespace

BuiltTree build_tree(const Json& root, const skill::SkillLibrary& library, const Limits& limits,
                     bt::Seconds default_stop_timeout, std::vector<Error>& errors, std::vector<ErrorCode>& codes) {
  BuiltTree out;
  Builder builder(library, limits, errors, codes, out);
  if (const auto index = builder.add(root, "/root", "root", default_stop_timeout, 1)) {
    out.tree.root = *index;
  }
  return out;
}

void check_reachability(const bt::TreeSpec& tree, std::vector<Error>& errors) {
  const auto& nodes = tree.nodes;
  const auto can = bt::compute_can_succeed(tree);
  // explained[i]: an error already says why node i can never succeed; its ancestors need not repeat it.
  std::vector<bool> explained(nodes.size(), false);
  auto blocking = [&](NodeIndex parent, NodeIndex child, const std::string& consequence) {
    if (!can[child] && !explained[child]) {
      const bt::NodeSpec& c = nodes[child];
      const std::string what = c.kind == NodeKind::kMonitor ? "a Monitor never succeeds"
                                                            : "this " + std::string(bt::to_string(c.kind)) +
                                                                  " can never succeed (it only ends by failing)";
      errors.push_back({c.pointer, what + ", so the " + std::string(bt::to_string(nodes[parent].kind)) + " " +
                                       consequence +
                                       "; expected a child that can succeed (put monitors in a Parallel beside "
                                       "the skill they watch)"});
    }
  };
  for (NodeIndex i = nodes.size(); i-- > 0;) {
    const bt::NodeSpec& node = nodes[i];
    bool any_unexplained_child = false;
    for (const NodeIndex c : node.children) {
      any_unexplained_child = any_unexplained_child || (!can[c] && !explained[c]);
    }
    switch (node.kind) {
      case NodeKind::kParallel: {
        std::size_t able = 0;
        for (const NodeIndex c : node.children) {
          able += can[c] ? 1 : 0;
        }
        if (node.success_threshold > able) {
          errors.push_back({node.pointer + "/success_threshold",
                            "success_threshold " + std::to_string(node.success_threshold) +
                                " can never be reached: only " + std::to_string(able) + " of " +
                                std::to_string(node.children.size()) +
                                " children can succeed (monitors never do); expected " +
                                (able == 0 ? std::string("at least one child that can succeed")
                                           : "1.." + std::to_string(able))});
          explained[i] = true;
        }
        if (node.failure_threshold > node.children.size()) {
          errors.push_back({node.pointer + "/failure_threshold",
                            "failure_threshold " + std::to_string(node.failure_threshold) + " exceeds the " +
                                std::to_string(node.children.size()) + " children; expected 1.." +
                                std::to_string(node.children.size())});
        }
        explained[i] = explained[i] || (!can[i] && !any_unexplained_child);
        break;
      }
      case NodeKind::kSequence:
        for (const NodeIndex c : node.children) {
          blocking(i, c, "can never succeed");
        }
        explained[i] = !can[i];
        break;
      case NodeKind::kRetry:
      case NodeKind::kRepeat:
        blocking(i, node.children.front(), "can never succeed");
        explained[i] = !can[i];
        break;
      default:
        // Fallback, OperatorDecision, Timeout: cannot succeed only when their children cannot.
        explained[i] = !can[i] && !node.children.empty() && !any_unexplained_child;
        break;
    }
  }
  if (!nodes.empty() && !can[tree.root] && !explained[tree.root]) {
    errors.push_back({nodes[tree.root].pointer,
                      "this recipe can never succeed (its top node only ends by failing); expected a tree that "
                      "can succeed"});
  }
}

void check_resources(const bt::TreeSpec& tree, std::vector<Error>& errors) {
  const auto& nodes = tree.nodes;
  // claims[i]: resource → first leaf in i's subtree claiming it.
  std::vector<std::map<std::string, NodeIndex>> claims(nodes.size());
  for (NodeIndex i = nodes.size(); i-- > 0;) {
    const bt::NodeSpec& node = nodes[i];
    auto& mine = claims[i];
    for (const auto& r : node.resources) {
      mine.emplace(r, i);
    }
    // (leaf in a later branch, leaf in an earlier branch) → resources both claim.
    std::map<std::pair<NodeIndex, NodeIndex>, std::vector<std::string>> conflicts;
    for (const NodeIndex c : node.children) {
      for (const auto& [resource, leaf] : claims[c]) {
        const auto [it, inserted] = mine.emplace(resource, leaf);
        if (!inserted && node.kind == NodeKind::kParallel) {
          conflicts[{leaf, it->second}].push_back(resource);
        }
      }
      claims[c].clear();  // no longer needed: keeps memory linear in the tree's width
    }
    for (const auto& [leaves, resources] : conflicts) {
      std::string names;
      for (std::size_t r = 0; r < resources.size(); ++r) {
        names += (r == 0 ? "\"" : ", \"") + resources[r] + "\"";
      }
      errors.push_back({nodes[leaves.first].pointer,
                        (resources.size() == 1 ? "resource " + names + " is" : "resources " + names + " are") +
                            " claimed both by " + describe_leaf(nodes[leaves.first]) + " and by " +
                            describe_leaf(nodes[leaves.second]) + ", which run concurrently under the Parallel at " +
                            node.pointer + "; expected concurrent branches to claim distinct resources"});
    }
  }
}

void check_preconditions(const BuiltTree& built, const std::vector<skill::Fact>& initial, std::vector<Error>& errors) {
  if (built.tree.nodes.empty()) {
    return;
  }
  FactFlow flow(built, initial, errors);
  flow.run_tree(built.tree.root);
}

}  // namespace rigger::recipe::detail
