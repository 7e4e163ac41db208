#pragma once
// The skill-event reaction of the task controller as real processes, shared by task_controller_live_bench
// (loopback, plain) and bench_network_matrix (test/bench: loopback or two lab hosts, security off or on):
// the controller and two scripted executors as real processes, an executor's event written -> the command
// it causes taken by the other executor (pattern A: a monitor's FAILURE -> the sibling skill's SHUTDOWN;
// pattern B: a leaf's SUCCESS -> the next leaf's START).
//
// Where the figures come from: the event's stamp (its writer's wall clock) and the controller's stages
// from the controller's stage trace (stage_trace_path); the command's stamp and the instant the skill
// executor's command handler began from that executor's receipt trace (scripted_executor's
// receipt_trace_path). This process reads neither skill events nor skill commands: it adds no reader to
// the path it measures (each reader a sample goes to is one more send, and one more woken process on a
// 2-core machine). One host, one clock (lab hosts share the kernel's).
#include <cstddef>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "rigger/dds/pubsub.hpp"
#include "rigger/protocol/task.hpp"
#include "rigger/testing/cell.hpp"

namespace rigger::bench {

/// One line of scripted_executor's receipt trace: a command it took, or an event it wrote (kind 100 +
/// the event's kind, stamped as written).
struct Receipt {
  std::string executor_id, task_id, node_id;
  int kind = 0;
  std::int64_t stamp_wall_ns = 0, woke_wall_ns = 0;
};
/// The receipt trace at `path` (empty when missing).
std::vector<Receipt> read_receipts(const std::string& path);

/// Writes `text` to `path` and returns `path`.
std::string write_file(const std::string& path, const std::string& text);

/// The bench's own endpoints on the task topics: it submits and cancels recipes and follows task statuses.
struct Observer {
  explicit Observer(rigger::testing::Cell& cell);

  void submit(const std::string& task_id, const nlohmann::json& recipe);
  void cancel(const std::string& task_id);

  rigger::dds::Writer<rigger_task_Recipe> recipes;
  rigger::dds::Writer<rigger_task_TaskCommand> task_commands;
  rigger::dds::Reader<rigger_task_TaskStatus> statuses;
  std::uint64_t seq = 0;
};

enum class Pattern {
  /// The paper's pattern, repeated: Repeat(trials, ForceSuccess(Parallel(1, 1)[skill, monitor])). The
  /// skill (Localize on executor "skills") runs until shut down; the monitor (TimerMonitor on executor
  /// "monitors") fails `period_ms` after its START. Measured: the FAILURE -> the skill's SHUTDOWN.
  kMonitorFailure,
  /// A sequence, repeated: Repeat(trials / 2, Sequence[Pick, Pick]) on executor "skills", each
  /// succeeding `period_ms` after its START; "monitors" runs too, idle. Measured: a leaf's SUCCESS -> the
  /// next leaf's START.
  kSuccessNext,
};

struct Reaction {
  // Per trial, from the event that causes the command (its executor's stamp) to:
  std::vector<double> command_written_us;   ///< the controller's command stamp (1 hop + handling)
  std::vector<double> command_received_us;  ///< the executor's command handler began (2 hops + handling)
  std::vector<double> stopped_written_us;   ///< the skill executor's STOPPED stamp (pattern A)
  // Per trial, one stage each (the controller's stage trace; they add up to command_received_us but
  // for the clock reads between them):
  std::vector<double> to_woke_us;          ///< event written → controller's handler woke (DDS, 1 hop)
  std::vector<double> to_writing_us;       ///< woke → command handed to DDS (take, engine until the write)
  std::vector<double> writing_us;          ///< the command's write call
  std::vector<double> to_engine_us;        ///< command written → engine returned
  std::vector<double> to_flushed_us;       ///< engine returned → journal rows and node statuses written
  std::vector<double> command_to_seen_us;  ///< command stamped → the executor woke (DDS, 1 hop)
  double trials_per_s = 0;
  /// Commands for the skill's executor that the monitors' executor took too (0 when every command went in
  /// the skill executor's partition; the first START of a run may go in the default one, before matching).
  std::size_t misrouted = 0;
  /// STARTs the controller sent again because no answer came in start_resend_s (its journal's
  /// START_SENT_AGAIN rows): 0 when no command was lost.
  std::size_t sent_again = 0;
  std::size_t stray_stopped = 0;  ///< STOPPED without a SHUTDOWN (only with ReactionSetup::allow_stray_stopped)
  /// The relay floor's figures (ReactionSetup::relay): the same trials through bench/relay_floor.cpp, which
  /// does the hop and nothing else, against the same executors and receipt traces, after the controller's.
  struct Floor {
    std::vector<double> command_written_us;   ///< event stamp → the relay's command stamp
    std::vector<double> command_received_us;  ///< event stamp → the executor's command handler began
    std::vector<double> to_woke_us;           ///< event stamp → the relay's waitset returned
    std::vector<double> handling_us;          ///< the relay woke → its write returned (take, write)
  } relay;
  /// With ReactionSetup::tail_fraction: the slowest trials' timelines (the controller's stages, every
  /// dispatch of its loop near them), then what overlapped the event's way in, counted over them.
  std::string tail;
  /// The controller's peak resident memory (VmHWM) and its resident memory at the end of the trials, KiB.
  long controller_peak_kib = 0;
  long controller_rss_kib = 0;
  /// Nodes of the recipe as run.
  int tree_nodes = 0;
  bool ok = false;
};

/// Starts one of the reaction's processes in `cell`: `name` is "tc" (task_controller), "skills" or
/// "monitors" (scripted_executor), `binary` a name in the build's bin/.
using StartProcess = std::function<rigger::testing::ChildProcess&(
    rigger::testing::Cell& cell, const std::string& name, const std::string& binary, std::vector<std::string> args)>;

/// Where the reaction runs. The defaults: this host, the cell's DDS configuration, the cell's own log folder.
struct ReactionSetup {
  std::string cell_subfolder;  ///< Cell(subfolder): its own log folder and journal for each setup of a run
  StartProcess start;          ///< empty: cell.start(name, binary, args)
  int warmup_trials = 0;       ///< trials of a task "warmup" run first and left out of the figures
  /// The skill's executor may stop the skill on its own (CONTROLLER_LOST when the controller's liveliness
  /// lapsed on a loaded machine): more STOPPED than FAILURE then still gives the FAILURE -> SHUTDOWN
  /// figures, counts the extra ones and leaves stopped_written_us empty. false: such a run fails.
  bool allow_stray_stopped = false;
  /// After the controller's trials, stop the controller and run the same trials through the relay floor
  /// (Reaction::relay). Needs task_controller_relay_floor in the build's bin/.
  bool relay = false;
  /// > 0: Reaction::tail holds the timelines of this fraction of the trials, the slowest (0.01: 1 %).
  double tail_fraction = 0;
  /// > 0: the recipe has about this many nodes: Fallback[the pattern's tree, Sequence[leaves…]], the
  /// leaves never started (the pattern's tree succeeds). How the cost grows with the tree.
  int tree_nodes = 0;
};

/// Runs `trials` trials of `pattern`. The Cell (and so this process's participant) is made here, with
/// CYCLONEDDS_URI as it is now; the trials start once this process's endpoints matched the controller's.
/// `ok` is false, and what went wrong is on stderr, when a process did not start, an endpoint did not
/// match, or the trials did not finish or pair.
Reaction measure_reaction(Pattern pattern, const std::string& journal_sync, int trials, int period_ms,
                          const ReactionSetup& setup = {});

}  // namespace rigger::bench
