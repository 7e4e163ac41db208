#pragma once
/// @file
/// Resume after a crash (pure): from an INTERRUPTED task's journal timeline, how its rebuilt tree is
/// taken up (a bt::Restoration) and what to tell the operator before anything runs. The rules are in
/// docs/behavior-tree.md "Resume after a crash":
///  - a node that reached SUCCESS is done and does not run again (nothing below it runs);
///  - a node that FAILED or was STOPPED while its parent ran on (a Fallback's failed alternative, a
///    Parallel's counted child) reports that result again at once;
///  - a node RUNNING at the crash runs again: a control node continues after its finished children (a
///    Retry keeps its failed runs, a Repeat its successes, an OperatorDecision the operator's choice);
///    a leaf starts again — a Skill only when its recipe node says `restartable`, otherwise the
///    operator decides; a Monitor or Condition (they move nothing) always;
///  - a Condition that succeeded right before a running Sequence's next child (only Conditions in
///    between) is evaluated again: it guards what runs next, and the world may have changed;
///  - a node STOPPING at the crash was being shut down by a deciding parent: it is taken as STOPPED
///    (the executors stopped every run of the lost controller);
///  - a task whose root was STOPPING (being canceled) or had finished is not resumed.

#include <set>
#include <string>
#include <vector>

#include "journal.hpp"
#include "rigger/bt/engine.hpp"
#include "rigger/bt/tree_spec.hpp"

namespace rigger::task_controller {

struct ResumePlan {
  bt::Restoration restoration;    ///< for Engine::start(const Restoration&)
  std::vector<std::string> done;  ///< outermost nodes done before the crash (not run again), in tree order
  /// Leaves that start again by rule: interrupted restartable skills, monitors and conditions, and the
  /// conditions guarding a running Sequence's next child.
  std::vector<std::string> rerun;
  std::vector<std::string> ask;      ///< interrupted skills that are not restartable: the operator decides
  std::vector<std::string> pending;  ///< leaves not started yet, run when their parent reaches them
  /// Leaves done before the crash that run again because the world changed under them (a localization of
  /// an object that moved while the controller was down: relocalization.hpp); their done ancestors are
  /// taken up as running, their done siblings stay done.
  std::vector<std::string> relocalize;
  std::string error;                 ///< why the task cannot be resumed; "" when it can
};

/// The plan for `spec` (the recipe's tree, rebuilt) from the task's journal `timeline` (its NODE rows,
/// in order). A NODE row naming a node the tree does not have, or a state no node has, is an error
/// (the journal does not belong to this recipe or is corrupt). `again`: ids of leaves that had succeeded
/// and run again (relocalize): each ancestor done with them is taken up as running (a Sequence starts
/// them, then reports its other done children at once; a Repeat counts one success less), everything
/// else done stays done. An id in `again` that is not a leaf that succeeded on a path of successes
/// below a running node is ignored.
ResumePlan plan_resume(const bt::TreeSpec& spec, const std::vector<JournalRecord>& timeline,
                       const std::set<std::string>& again = {});

/// The operator's `skip`: every `ask` leaf is taken as done (SUCCESS) instead of started again.
void skip_interrupted(ResumePlan& plan, const bt::TreeSpec& spec, const std::string& by);

/// "root/0 (MoveTo)": a node for people.
std::string describe_node(const bt::TreeSpec& spec, const std::string& node_id);
/// The plan for people, one part per line: "done: …", "runs again: …", "re-localized: …" (when any),
/// "operator decides: …", "then: …".
std::string describe_plan(const ResumePlan& plan, const bt::TreeSpec& spec);

}  // namespace rigger::task_controller
