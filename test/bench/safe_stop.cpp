// How fast the supervisor's stops reach moving devices (docs/safety.md), on the whole simulated cell (real
// processes, MuJoCo physics, loopback). The robot localizes the load and attaches itself to it once;
// then each trial runs CollaborativeMoveLoad with the operator's joystick (written here at 50 Hz, 5 cm/s,
// alternately +x and -x) so that robot and crane carry the load under admittance control, and, once both
// move faster than 2 cm/s, breaks the supervision:
//  - kill: the task controller is SIGKILLed. The executor sees the controller's command-writer lease
//    lapse and shuts the skill down (CONTROLLER_LOST). Measured: the kill → robot tool and crane both
//    below 1 mm/s. The reference is that lease (command_lease_ms): no executor can know sooner.
//  - escalation: the skill's executor is frozen (SIGSTOP: a skill that ignores SHUTDOWN) while the
//    joystick keeps pushing, and the task is cancelled: the controller's SHUTDOWN goes unanswered, and
//    when the executor's liveliness lapses (its 150 ms lease) or the recipe's stop timeout (0.5 s)
//    passes, whichever is first, it commands the safe stop of the leaf's devices (rigger/safety/stop).
//    Measured: the freeze → the stop on the wire, and the stop → both below 1 mm/s. Then the executor
//    is let go (SIGCONT) and the stops are reset (riggerctl estop --reset).
// Each trial's figure is ScenarioCell's rest_after_mark_s(): from the mark to the first moment at which the
// newest tool twist (rigger/robot/state) and the newest crane velocity of the simulator (rigger/sim/status)
// are both below 1 mm/s, timed by the samples' stamps.
//
//   build/bench/bench_safe_stop [--trials 20]
#include <signal.h>

#include <cstdio>
#include <optional>
#include <string>
#include <vector>

#include "bench_util.hpp"
#include "rigger/dds/conversions.hpp"
#include "rigger/dds/pubsub.hpp"
#include "rigger/protocol/operator.hpp"
#include "rigger/protocol/robot.hpp"
#include "rigger/protocol/task.hpp"
#include "rigger/safety/safe_stop.hpp"
#include "scenario_support.hpp"

namespace {

using namespace std::chrono_literals;
using nlohmann::json;
using rigger::testing::Cell;
using rigger::testing::scenario::Clock;
using rigger::testing::scenario::ScenarioCell;

constexpr double kMovingMps = 0.02;    // a trial breaks the supervision once both move faster than this
constexpr double kJogMps = 0.05;       // the joystick's push
constexpr double kStopTimeoutS = 0.5;  // the recipe's stop timeout (escalation trials)

/// Whether robot tool and crane both move (faster than kMovingMps), as this process reads them. When they
/// are still again after a stop, ScenarioCell says (mark_stop(), rest_after_mark_s()).
class Motion {
 public:
  Motion(Cell& cell, rigger::testing::SimChannel& sim)
      : robot_(cell.participant(), rigger::protocol::robot::kState), sim_(sim) {
    cell.loop().on_data(robot_, [this] {
      robot_.take([this](const rigger_robot_RobotState& s, const dds_sample_info_t&) {
        const auto& v = s.tool_twist.linear;
        tool_mps_ = Eigen::Vector3d(v.x, v.y, v.z).norm();
      });
    });
  }
  bool moving() const {
    return tool_mps_ > kMovingMps && sim_.has_status() && sim_.latest().crane_velocity_mps.norm() > kMovingMps;
  }

 private:
  rigger::dds::Reader<rigger_robot_RobotState> robot_;
  rigger::testing::SimChannel& sim_;
  double tool_mps_ = 0.0;
};

/// The operator's joystick, written on the cell's loop at 50 Hz while on.
class Joystick {
 public:
  explicit Joystick(Cell& cell) : writer_(cell.participant(), rigger::protocol::operator_ui::kJoystick) {
    cell.loop().every(20ms, [this] {
      if (on_) write(speed_);
    });
  }
  void push(double speed_x) { on_ = true, speed_ = speed_x; }
  void release() {
    on_ = false;
    write(0.0);
  }

 private:
  void write(double speed_x) {
    rigger_sensing_TwistCommand c{};
    c.header.stamp = rigger::dds::wire_now();
    c.header.frame_id = rigger::dds::wire_string("base");
    c.seq = ++seq_;
    rigger::dds::Vector6d v = rigger::dds::Vector6d::Zero();
    v[0] = speed_x;
    c.twist = rigger::dds::to_wire_twist(v);
    c.timeout_s = 0.2;
    c.source = rigger::dds::wire_string("bench_safe_stop");
    writer_.write(c);
  }
  rigger::dds::Writer<rigger_sensing_TwistCommand> writer_;
  bool on_ = false;
  double speed_ = 0.0;
  std::uint64_t seq_ = 0;
};

json guide_recipe(const std::string& task_id, double stop_timeout_s) {
  return {{"recipe_version", 1},
          {"task_id", task_id},
          {"description", "bench_safe_stop: the load guided by the joystick"},
          {"assumptions", {"hooked(crane,load)", "attached(robot,load)"}},
          {"stop_timeout_s", stop_timeout_s},
          {"root",
           {{"type", "Skill"},
            {"skill", "CollaborativeMoveLoad"},
            {"name", "guide load"},
            {"params", {{"object", "load"}, {"reference", "joystick"}}}}}};
}

void print_row(const char* what, const std::vector<double>& ms, const std::string& reference) {
  using rigger::bench::percentile;
  std::printf("%-52s %8.0f %8.0f %8.0f %6zu  %s\n", what, percentile(ms, 0.5), percentile(ms, 0.99),
              ms.empty() ? 0.0 : *std::max_element(ms.begin(), ms.end()), ms.size(), reference.c_str());
}

}  // namespace

int main(int argc, char** argv) {
  const int trials = rigger::bench::int_option(argc, argv, "--trials", 20);
  Cell cell;
  // The guided move asks the operator for 'done'; nobody answers within a trial.
  ScenarioCell s(cell, {"confirm:object=load:done@3600"});
  if (!s.ready()) {
    std::fprintf(stderr, "bench_safe_stop: not every service came up\n%s", cell.logs().c_str());
    return 1;
  }
  Motion motion(cell, s.sim());
  Joystick joystick(cell);
  rigger::dds::Writer<rigger_task_TaskCommand> commands(cell.participant(), rigger::protocol::task::kCommand);
  std::optional<Clock::time_point> stop_seen;
  rigger::safety::SafeStopListener stops(cell.participant(), cell.loop(), rigger::safety::stoppable_resources(),
                                         [&](const std::string&, const rigger::safety::StopState& st) {
                                           if (st.active && !stop_seen) stop_seen = Clock::now();
                                         });
  const auto fail = [&](const std::string& why) {
    std::fprintf(stderr, "bench_safe_stop: %s\n%s\n%s", why.c_str(), s.task_summary().c_str(), cell.logs().c_str());
    return 1;
  };

  // Localize the load and attach the robot to it, once (guide_by_joystick.json's first two steps).
  {
    std::ifstream in(rigger::testing::repo_file("recipes/examples/guide_by_joystick.json"));
    json attach = json::parse(in);
    attach["task_id"] = "bench-attach";
    auto& children = attach["root"]["children"];
    children = json::array({children[0], children[1]});
    if (!s.submit_json(attach) || !s.wait_task_end(180s) || s.task_state() != rigger_task_TASK_SUCCEEDED)
      return fail("the robot did not attach itself to the load");
  }

  std::string controller = "task_controller";
  std::vector<double> kill_ms, stop_ms, freeze_to_stop_ms;
  for (int i = 0; i < 2 * trials; ++i) {
    const bool kill = i % 2 == 0;
    const std::string task = std::string(kill ? "kill-" : "escalate-") + std::to_string(i / 2);
    if (!s.submit_json(guide_recipe(task, kill ? 5.0 : kStopTimeoutS))) return fail("no controller reads recipes");
    if (!s.wait_node("guide load", rigger_task_NODE_RUNNING, 30s) ||
        s.node("guide load")->state != rigger_task_NODE_RUNNING)
      return fail(task + ": the guided move did not start");
    joystick.push((i / 2) % 2 == 0 ? kJogMps : -kJogMps);
    if (!cell.wait_until([&] { return motion.moving(); }, 15s)) return fail(task + ": robot and crane did not move");

    if (kill) {
      s.mark_stop(Clock::now());
      if (!cell.stop(controller, SIGKILL, 5s)) return fail("the controller did not end on SIGKILL");
      if (!cell.wait_until([&] { return s.rest_after_mark_s().has_value(); }, 10s))
        return fail(task + ": still moving");
      kill_ms.push_back(*s.rest_after_mark_s() * 1000.0);
      joystick.release();
      // The killed controller's recipe reader must be gone before the next one's is counted (its
      // participant lease is 1 s); then a new controller on the same journal.
      if (!cell.wait_until([&] { return s.recipe_readers() == 0; }, 10s)) return fail("the killed controller lingers");
      controller = "tc-" + std::to_string(i);
      if (!s.restart_controller(controller)) return fail("the controller did not restart");
      if (!cell.wait_until([&] { return s.recipe_readers() == 1; }, 10s)) return fail("no recipe reader after restart");
    } else {
      rigger::testing::ChildProcess& executor = cell.process("robot-skills");
      stop_seen.reset();
      const auto frozen_at = Clock::now();
      executor.signal(SIGSTOP);
      rigger_task_TaskCommand c{};
      c.task_id = rigger::dds::wire_string(task);
      c.kind = rigger_task_TASK_CANCEL;
      c.reason = rigger::dds::wire_string("bench_safe_stop: escalation trial");
      c.issuer = rigger::dds::wire_string("bench_safe_stop");
      c.seq = static_cast<std::uint64_t>(i + 1);
      c.stamp = rigger::dds::wire_now();
      commands.write(c);
      const bool stopped = cell.wait_until([&] { return stop_seen.has_value(); }, 10s);
      if (stopped) {
        s.mark_stop(*stop_seen);
        freeze_to_stop_ms.push_back(std::chrono::duration<double, std::milli>(*stop_seen - frozen_at).count());
      }
      const bool still = stopped && cell.wait_until([&] { return s.rest_after_mark_s().has_value(); }, 10s);
      joystick.release();
      executor.signal(SIGCONT);
      if (!stopped) return fail(task + ": no safe stop was commanded");
      if (!still) return fail(task + ": still moving after the safe stop");
      stop_ms.push_back(*s.rest_after_mark_s() * 1000.0);
      if (!s.wait_task_end(30s)) return fail(task + ": the cancelled task did not end");
      // The operator's reset, as riggerctl does it: it returns once every device acknowledged it.
      const auto reset = rigger::testing::run_riggerctl(cell, "reset-" + std::to_string(i), {"estop", "--reset"});
      if (reset.code() != 0) return fail("riggerctl estop --reset failed: " + reset.output);
      if (!cell.wait_until([&] { return s.crane_ready(); }, 10s))
        return fail("the crane did not come back after the reset");
    }
    std::printf("  %-12s %6.0f ms\n", task.c_str(), kill ? kill_ms.back() : stop_ms.back());
    std::fflush(stdout);
  }
  joystick.release();
  cell.stop_all();

  std::printf(
      "Stops reaching moving devices: robot and crane carrying the 40 kg load under admittance control,\n"
      "%d trials each, whole simulated cell on loopback, domain %u\n",
      trials, cell.domain_id());
  std::printf("%-52s %8s %8s %8s %6s  %s\n", "", "p50 ms", "p99 ms", "max ms", "trials", "reference");
  print_row("controller SIGKILL -> robot and crane < 1 mm/s", kill_ms,
            "command lease " + std::to_string(rigger::dds::liveliness_lease().count()) +
                " ms (command_lease_ms: its default, which the shipped file keeps)");
  print_row("executor frozen, task cancelled -> safe stop written", freeze_to_stop_ms,
            "executor lease " + std::to_string(rigger::dds::liveliness_lease().count()) + " ms, stop timeout " +
                std::to_string(static_cast<int>(kStopTimeoutS * 1000)) + " ms");
  print_row("safe stop written -> robot and crane < 1 mm/s", stop_ms, "");

  rigger::performance::Report report(
      "bench_safe_stop", "Stops reaching the robot and the crane carrying the 40 kg load under admittance control, " +
                             std::to_string(trials) +
                             " trials each, whole simulated cell on loopback, next to the leases that bound them");
  const double lease_ms = static_cast<double>(rigger::dds::liveliness_lease().count());
  const auto add = [&](const std::string& what, const std::vector<double>& ms, const std::string& reference) {
    using rigger::bench::percentile;
    const std::pair<const char*, double> levels[] = {
        {" p50", percentile(ms, 0.5)}, {" p99", percentile(ms, 0.99)}, {" max", percentile(ms, 1.0)}};
    for (const auto& [level, value] : levels)
      report.add({what + level, value, "ms", reference, reference.empty() ? 0 : lease_ms});
  };
  add("controller SIGKILL -> at rest", kill_ms, "command lease");
  add("executor frozen, task cancelled -> safe stop written", freeze_to_stop_ms,
      "executor lease (stop timeout " + std::to_string(static_cast<int>(kStopTimeoutS * 1000)) + " ms)");
  add("safe stop written -> at rest", stop_ms, "");
  return rigger::performance::save_for_main(report);
}
