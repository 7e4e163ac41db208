// A wrench from a ROS 2 force-torque broadcaster to the twist MoveIt Servo receives, through rigger's
// ROS 2 bridge and its admittance control (docs/ros2.md "What the bridge costs"), next to the
// same chain without the bridge, in the same run:
//
//   with the bridge  geometry_msgs/WrenchStamped on rt/force_torque_sensor_broadcaster/wrench (sensor_data)
//                    -> ros2_bridge -> rigger/robot/wrench -> admittance_control -> rigger/robot/cmd_twist
//                    -> ros2_bridge -> geometry_msgs/TwistStamped on rt/servo_node/delta_twist_cmds
//   direct           rigger/robot/wrench -> admittance_control -> rigger/robot/cmd_twist
//
// Real processes (ros2_bridge and admittance_control with their shipped configurations) on a private
// domain, loopback. admittance_control runs in mode ROBOT with no reference, the sensor upright (a robot
// state with the flange at identity). Each trial writes one wrench sample of 100 N along ±x or ±y,
// alternately by the ROS 2 topic (four trials) and by rigger's (four trials), and times it from the
// moment it is written to the arrival of the first twist it causes. Which twist that is, is exact: between
// trials no wrench is written, so the law's wrench goes stale (wrench_timeout_s 20 ms) and it commands an
// exact zero and forgets its motion; a trial starts only once both twist topics show that zero again, and
// the first non-zero cmd_twist after the trial's wrench must point along its force (a twist that does not
// is counted, not timed). Through the bridge, the TwistStamped timed is the one carrying that cmd_twist's
// stamp (the bridge passes stamps through). Both figures include the wait for the law's next 500 Hz
// cycle (0-2 ms, uniform when the trials' phase sweeps it: the trial period is not a multiple of 2 ms).
//
//   build/bench/bench_ros2_admittance [--trials 1000] [--period-us 50300]   (trials of both paths together)
#include <cmath>
#include <cstdio>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "bench_util.hpp"
#include "rigger/dds/conversions.hpp"
#include "rigger/dds/pubsub.hpp"
#include "rigger/idl/types.hpp"
#include "rigger/protocol/admittance.hpp"
#include "rigger/protocol/robot.hpp"
#include "rigger/ros2/conversions.hpp"
#include "rigger/ros2/qos.hpp"
#include "rigger/ros2/types.hpp"
#include "rigger/testing/cell.hpp"

namespace {

using namespace std::chrono_literals;
using Clock = std::chrono::system_clock;

double us_between(Clock::time_point from, Clock::time_point to) {
  return std::chrono::duration<double, std::micro>(to - from).count();
}

std::int64_t stamp_key(std::int32_t sec, std::uint32_t nanosec) {
  return static_cast<std::int64_t>(sec) * 1'000'000'000 + nanosec;
}

/// One trial: a wrench written at `written`, along `direction`, by the ROS 2 topic or rigger's.
struct Trial {
  bool via_bridge = false;
  Eigen::Vector3d direction = Eigen::Vector3d::Zero();
  Clock::time_point written;
  std::optional<std::int64_t> command_stamp;           ///< the first non-zero cmd_twist's stamp
  Clock::time_point command_at;                        ///< its arrival here
  std::map<std::int64_t, Clock::time_point> servo_at;  ///< non-zero TwistStamped arrivals, by stamp
};

struct Figures {
  std::vector<double> bridge_us;          ///< written on rt/ -> TwistStamped received
  std::vector<double> direct_us;          ///< written on rigger/robot/wrench -> cmd_twist received
  std::vector<double> bridge_command_us;  ///< written on rt/ -> cmd_twist received (the wrench leg)
  std::vector<double> twist_leg_us;       ///< cmd_twist received -> the TwistStamped of the same stamp received
  int lost_bridge = 0, lost_direct = 0, wrong_direction = 0, skipped = 0;
};

/// Drives `trials` trials (after 8 for warm-up, half of them each way) at `period`, on `cell`'s loop; see the
/// header.
Figures measure(rigger::testing::Cell& cell, int trials, std::chrono::microseconds period) {
  namespace dds = rigger::dds;
  namespace protocol = rigger::protocol;
  dds::Writer<geometry_msgs_msg_dds__WrenchStamped_> ros2_wrench(
      cell.participant(), "rt/force_torque_sensor_broadcaster/wrench", rigger::ros2::qos::sensor_data());
  dds::Writer<rigger_sensing_WrenchStamped> wrench(cell.participant(), protocol::robot::kWrench);
  dds::Writer<rigger_robot_RobotState> robot_state(cell.participant(), protocol::robot::kState);
  dds::Writer<rigger_admittance_AdmittanceCommand> command(cell.participant(), protocol::admittance::kCommand);
  dds::Reader<rigger_sensing_TwistCommand> cmd_twist(cell.participant(), protocol::robot::kCmdTwist);
  dds::Reader<geometry_msgs_msg_dds__TwistStamped_> servo(cell.participant(), "rt/servo_node/delta_twist_cmds",
                                                          rigger::ros2::qos::reliable_default());
  Figures out;
  if (!ros2_wrench.wait_for_readers(1, 10s) || !wrench.wait_for_readers(1, 10s) || !command.wait_for_readers(1, 10s) ||
      !robot_state.wait_for_readers(1, 10s) || !cmd_twist.wait_for_writers(1, 10s) || !servo.wait_for_writers(1, 10s)) {
    std::fprintf(stderr, "the bridge or admittance_control did not match the bench's topics\n");
    return out;
  }
  // The sensor upright: the law turns the wrench into the base frame with the flange's orientation.
  const auto state_timer = cell.loop().every(100ms, [&] {
    rigger_robot_RobotState s{};
    s.header.stamp = dds::wire_now();
    s.flange_pose = dds::to_wire(Eigen::Isometry3d::Identity());
    s.tool_pose = s.flange_pose;
    robot_state.write(s);
  });
  rigger_admittance_AdmittanceCommand on{};
  on.header.stamp = dds::wire_now();
  on.seq = 1;
  on.mode = rigger_admittance_ADMITTANCE_ROBOT;
  on.reference = rigger_admittance_REFERENCE_NONE;
  command.write(on);

  std::optional<Trial> trial;
  bool command_at_rest = false, servo_at_rest = false;
  int started = 0;
  constexpr int kWarmUp = 8;
  // A trial ends when its command has come through both topics (the direct one too, so that the next
  // trial starts from rest on both).
  const auto try_finish = [&] {
    if (!trial || !trial->command_stamp || !trial->servo_at.count(*trial->command_stamp)) return;
    if (started > kWarmUp) {
      const Trial& t = *trial;
      const auto servo_at = t.servo_at.at(*t.command_stamp);
      if (t.via_bridge) {
        out.bridge_us.push_back(us_between(t.written, servo_at));
        out.bridge_command_us.push_back(us_between(t.written, t.command_at));
      } else {
        out.direct_us.push_back(us_between(t.written, t.command_at));
      }
      out.twist_leg_us.push_back(us_between(t.command_at, servo_at));
    }
    trial.reset();
  };
  cell.loop().on_data(cmd_twist, [&] {
    const auto now = Clock::now();
    cmd_twist.take([&](const rigger_sensing_TwistCommand& c, const dds_sample_info_t&) {
      const dds::Vector6d v = dds::to_domain(c.twist);
      command_at_rest = v.isZero(0.0);
      if (command_at_rest || !trial || trial->command_stamp) return;
      if (v.head<3>().normalized().dot(trial->direction) < 0.999) {
        ++out.wrong_direction;  // not this trial's: counted, and the trial is dropped
        trial.reset();
        return;
      }
      trial->command_stamp = stamp_key(c.header.stamp.sec, c.header.stamp.nanosec);
      trial->command_at = now;
    });
    try_finish();
  });
  cell.loop().on_data(servo, [&] {
    const auto now = Clock::now();
    servo.take([&](const geometry_msgs_msg_dds__TwistStamped_& t, const dds_sample_info_t&) {
      const auto& l = t.twist_.linear_;
      const auto& a = t.twist_.angular_;
      servo_at_rest = l.x_ == 0 && l.y_ == 0 && l.z_ == 0 && a.x_ == 0 && a.y_ == 0 && a.z_ == 0;
      if (!servo_at_rest && trial) trial->servo_at[stamp_key(t.header_.stamp_.sec_, t.header_.stamp_.nanosec_)] = now;
    });
    try_finish();
  });

  // Wait for the law to run (zero twists on both topics) before the first trial.
  if (!cell.wait_until([&] { return command_at_rest && servo_at_rest; }, 10s)) {
    std::fprintf(stderr, "no zero twist from admittance_control through the bridge within 10 s\n");
    cell.loop().cancel(state_timer);
    return out;
  }
  const std::vector<Eigen::Vector3d> directions = {Eigen::Vector3d::UnitX(), Eigen::Vector3d::UnitY(),
                                                   -Eigen::Vector3d::UnitX(), -Eigen::Vector3d::UnitY()};
  const auto trial_timer = cell.loop().every(period, [&] {
    // A trial whose command has not come 200 ms after its wrench is lost: the sample was lost (the first,
    // warm-up, one may be), or the law ran only after wrench_timeout_s (20 ms) and refused it as stale.
    // The slots before that are skipped, as are those while the last trial's motion is not over: under
    // load, the bench's own loop may also run a slot late and the next one at once.
    if (trial && Clock::now() - trial->written > 200ms) {
      if (started > kWarmUp) ++(trial->via_bridge ? out.lost_bridge : out.lost_direct);
      trial.reset();
    }
    if (trial || !command_at_rest || !servo_at_rest) {
      ++out.skipped;
      return;
    }
    Trial t;
    t.via_bridge = (started / 4) % 2 == 0;
    t.direction = directions[static_cast<std::size_t>(started % 4)];
    ++started;
    rigger_sensing_WrenchStamped w{};
    w.header.frame_id = const_cast<char*>("tool0");
    w.wrench.force = dds::to_wire_vector(100.0 * t.direction);
    t.written = Clock::now();
    w.header.stamp = dds::to_wire(t.written);
    trial = t;
    if (t.via_bridge) {
      ros2_wrench.write(rigger::ros2::to_ros2(w));  // as the driver's broadcaster writes it
    } else {
      wrench.write(w);
    }
  });
  cell.wait_until([&] { return started >= trials + kWarmUp && !trial; },
                  std::chrono::duration_cast<std::chrono::milliseconds>((trials + kWarmUp) * period * 3) + 10s);
  cell.loop().cancel(trial_timer);
  cell.loop().cancel(state_timer);
  return out;
}

void print_row(const char* what, const std::vector<double>& us) {
  using rigger::bench::percentile;
  std::printf("%-62s %9.1f %9.1f %9.1f %8zu\n", what, percentile(us, 0.5), percentile(us, 0.9), percentile(us, 0.99),
              us.size());
}

}  // namespace

int main(int argc, char** argv) {
  const int trials = rigger::bench::int_option(argc, argv, "--trials", 1000);
  const auto period = std::chrono::microseconds(rigger::bench::int_option(argc, argv, "--period-us", 50300));
  const std::string config_dir = std::string(RIGGER_SOURCE_DIR) + "/deploy/config/";
  rigger::testing::Cell cell;
  cell.start("ros2_bridge", "ros2_bridge",
             {"--id", "ros2_bridge", "--config", config_dir + "ros2_bridge.json", "--log-level", "warn"});
  cell.start("admittance_control", "admittance_control",
             {"--id", "admittance_control", "--config", config_dir + "admittance_control.json", "--log-level", "warn"});
  if (!cell.wait_ready({"ros2_bridge", "admittance_control"}, 10s)) {
    std::fprintf(stderr, "the bridge or admittance_control did not become ready\n%s", cell.logs().c_str());
    return 1;
  }
  const Figures f = measure(cell, trials, period);
  if (f.bridge_us.empty() || f.direct_us.empty()) {
    std::fprintf(stderr, "no trial came through\n%s", cell.logs().c_str());
    return 1;
  }
  const auto stopped = cell.stop_all();
  if (!stopped.ok) std::fprintf(stderr, "%s", stopped.problems.c_str());

  using rigger::bench::percentile;
  std::printf(
      "A wrench sample to the admittance command it causes, with and without the ROS 2 bridge: %d trials,\n"
      "one every %.1f ms, 100 N along +-x/+-y; loopback, domain %u\n",
      trials, static_cast<double>(period.count()) / 1000.0, cell.domain_id());
  std::printf("%-62s %9s %9s %9s %8s\n", "", "p50 us", "p90 us", "p99 us", "trials");
  print_row("ROS 2 wrench -> bridge -> admittance -> bridge -> ROS 2 twist", f.bridge_us);
  print_row("rigger wrench -> admittance -> rigger cmd_twist (direct)", f.direct_us);
  print_row("  of which, with the bridge: ROS 2 wrench -> rigger cmd_twist", f.bridge_command_us);
  print_row("  rigger cmd_twist -> bridge -> ROS 2 twist (same stamp)", f.twist_leg_us);
  std::printf("with / without the bridge: p50 %.2f  p90 %.2f  p99 %.2f; median difference %+.1f us\n",
              percentile(f.bridge_us, 0.5) / percentile(f.direct_us, 0.5),
              percentile(f.bridge_us, 0.9) / percentile(f.direct_us, 0.9),
              percentile(f.bridge_us, 0.99) / percentile(f.direct_us, 0.99),
              percentile(f.bridge_us, 0.5) - percentile(f.direct_us, 0.5));
  std::printf(
      "no command within 200 ms: %d with the bridge, %d direct; first twist along another direction: %d; "
      "slots skipped: %d\n",
      f.lost_bridge, f.lost_direct, f.wrong_direction, f.skipped);
  if (!stopped.ok) return 1;

  rigger::performance::Report report(
      "bench_ros2_admittance",
      "A wrench sample to the admittance command it causes, through the ROS 2 bridge both ways, " +
          std::to_string(trials) + " trials (100 N steps, one every " + std::to_string(period.count() / 1000) +
          " ms), loopback, next to the same chain on rigger's topics without the bridge");
  using rigger::bench::add_quantiles;
  using rigger::bench::quantiles;
  add_quantiles(report, "ROS 2 wrench -> ROS 2 twist", quantiles(f.bridge_us), "us", "rigger wrench -> cmd_twist",
                quantiles(f.direct_us));
  add_quantiles(report, "ROS 2 wrench -> rigger cmd_twist", quantiles(f.bridge_command_us), "us");
  add_quantiles(report, "rigger cmd_twist -> ROS 2 twist", quantiles(f.twist_leg_us), "us");
  report.add({"trials without a command within 200 ms, with the bridge", static_cast<double>(f.lost_bridge), "trials",
              "trials without a command within 200 ms, direct", static_cast<double>(f.lost_direct)});
  report.add({"first twist along another direction", static_cast<double>(f.wrong_direction), "trials", "", 0});
  return rigger::performance::save_for_main(report);
}
