// The crane gateway against the PLC emulator over real TCP on loopback, with a kinematic crane
// standing in for the physics.
#include <gtest/gtest.h>

#include <chrono>
#include <condition_variable>
#include <functional>
#include <memory>
#include <mutex>
#include <thread>

#include "crane_gateway.hpp"
#include "rigger/crane_protocol/testing.hpp"
#include "rigger/plc/kinematic_crane_axes.hpp"
#include "rigger/plc/plc_emulator.hpp"

namespace rigger::crane_gateway {
namespace {

using ::rigger::crane::testing::reference_limits;

using namespace std::chrono_literals;
using Clock = std::chrono::steady_clock;

plc::PlcEmulatorConfig plc_config(std::uint16_t port) {
  plc::PlcEmulatorConfig c;
  c.program.limits = reference_limits();
  c.server.port = port;
  return c;
}

constexpr auto kPlcPeriod = 4ms;

// Runs CraneGateway::cycle() every cycle_period on its own thread, like the service will, and
// lets the test wait for cycles or stall it (the test's stand-in for SIGSTOP).
class GatewayRunner {
 public:
  explicit GatewayRunner(CraneGateway& gateway) : gateway_(gateway) {
    thread_ = std::thread([this] { run(); });
  }
  ~GatewayRunner() {
    {
      const std::lock_guard<std::mutex> lock(mutex_);
      stop_ = true;
    }
    wake_.notify_all();
    thread_.join();
  }

  /// Stops cycling; returns when no cycle is in progress, with the end time of the last one.
  Clock::time_point pause() {
    std::unique_lock<std::mutex> lock(mutex_);
    paused_ = true;
    cycled_.wait(lock, [this] { return !in_cycle_; });
    return last_cycle_end_;
  }
  void resume() {
    const std::lock_guard<std::mutex> lock(mutex_);
    paused_ = false;
  }

  /// Waits until `predicate(state)` holds after some cycle; false on timeout.
  bool wait_for(const std::function<bool(const GatewayState&)>& predicate,
                std::chrono::nanoseconds timeout) {
    std::unique_lock<std::mutex> lock(mutex_);
    return cycled_.wait_for(lock, timeout, [&] { return predicate(gateway_.state()); });
  }
  /// Waits for `n` more cycles.
  bool wait_cycles(std::uint64_t n, std::chrono::nanoseconds timeout = 2s) {
    std::unique_lock<std::mutex> lock(mutex_);
    const std::uint64_t target = cycles_ + n;
    return cycled_.wait_for(lock, timeout, [&] { return cycles_ >= target; });
  }
  CycleReport last_report() {
    const std::lock_guard<std::mutex> lock(mutex_);
    return last_report_;
  }

 private:
  void run() {
    const auto period = gateway_.config().cycle_period;
    auto next = Clock::now();
    std::unique_lock<std::mutex> lock(mutex_);
    while (!stop_) {
      if (!paused_) {
        in_cycle_ = true;
        lock.unlock();
        CycleReport report = gateway_.cycle();
        lock.lock();
        in_cycle_ = false;
        last_report_ = std::move(report);
        last_cycle_end_ = Clock::now();
        ++cycles_;
        cycled_.notify_all();
      }
      next += period;
      wake_.wait_until(lock, next, [this] { return stop_; });
    }
  }

  CraneGateway& gateway_;
  std::mutex mutex_;
  std::condition_variable cycled_;
  std::condition_variable wake_;
  bool stop_ = false;
  bool paused_ = false;
  bool in_cycle_ = false;
  std::uint64_t cycles_ = 0;
  Clock::time_point last_cycle_end_{};
  CycleReport last_report_;
  std::thread thread_;
};

class GatewayLoopback : public ::testing::Test {
 protected:
  GatewayLoopback() : axes({4.0, 2.5, 2.0}, 40.0) {
    start_plc(0);
    port = plc->port();
  }

  void start_plc(std::uint16_t on_port) {
    plc = std::make_unique<plc::PlcEmulator>(plc_config(on_port), axes);
    plc->start_server();
    plc->start_cycle_thread(kPlcPeriod, [this](std::chrono::nanoseconds dt) { axes.advance(dt); });
  }

  CraneGatewayConfig gateway_config(std::chrono::milliseconds command_timeout = 100ms) const {
    CraneGatewayConfig c;
    c.plc_port = port;
    c.logic.plausibility.limits = reference_limits();
    c.logic.command_timeout = command_timeout;
    return c;
  }

  void start_gateway(std::chrono::milliseconds command_timeout = 100ms) {
    gateway = std::make_unique<CraneGateway>(gateway_config(command_timeout));
    runner = std::make_unique<GatewayRunner>(*gateway);
  }

  /// Enables, requests external control and waits for the grant.
  void take_control() {
    gateway->set_control({true, true});
    ASSERT_TRUE(runner->wait_for(
        [](const GatewayState& s) { return s.link_up && s.external_control_granted; }, 3s))
        << gateway->state().fault_reason;
  }

  CommandVerdict send(const Eigen::Vector3d& velocity_mps) {
    VelocityCommand c;
    c.velocity_mps = velocity_mps;
    c.stamp = std::chrono::system_clock::now();
    c.seq = ++seq;
    return gateway->submit_command(c);
  }

  /// Keeps sending `velocity_mps` once per gateway cycle for `duration`.
  void drive(const Eigen::Vector3d& velocity_mps, std::chrono::nanoseconds duration) {
    const auto end = Clock::now() + duration;
    while (Clock::now() < end) {
      send(velocity_mps);
      ASSERT_TRUE(runner->wait_cycles(1));
    }
  }

  void TearDown() override {
    runner.reset();
    gateway.reset();
    plc.reset();
  }

  plc::KinematicCraneAxes axes;
  std::unique_ptr<plc::PlcEmulator> plc;
  std::uint16_t port = 0;
  std::unique_ptr<CraneGateway> gateway;
  std::unique_ptr<GatewayRunner> runner;
  std::uint64_t seq = 0;
};

TEST_F(GatewayLoopback, MovesTheCraneToACommandedPosition) {
  start_gateway();
  take_control();
  const Eigen::Vector3d target(4.6, 2.1, 2.3);
  constexpr double kGain = 1.5;  // 1/s
  const auto deadline = Clock::now() + 15s;
  bool arrived = false;
  while (!arrived && Clock::now() < deadline) {
    ASSERT_TRUE(runner->wait_cycles(1));
    const GatewayState state = gateway->state();
    // A response late beyond the 50 ms timeout (a loaded test machine) drops the link; the
    // gateway reconnects and the loop goes on with fresh commands.
    if (!state.link_up || !state.plc) {
      continue;
    }
    ASSERT_NE(state.fault, GatewayFault::kImplausibleState) << state.fault_reason;
    ASSERT_NE(state.fault, GatewayFault::kPlcFault) << state.fault_reason;
    const Eigen::Vector3d error = target - state.plc->position_m;
    arrived = error.cwiseAbs().maxCoeff() < 0.003 && state.plc->velocity_mps.norm() < 0.01;
    send(kGain * error);
  }
  ASSERT_TRUE(arrived) << "crane at " << axes.read().position_m.transpose();
  EXPECT_LT((axes.read().position_m - target).cwiseAbs().maxCoeff(), 0.005);
  const auto snapshot = plc->snapshot();
  EXPECT_FALSE(snapshot.status.flags.fault);
  const GatewayState state = gateway->state();
  EXPECT_EQ(state.implausible_states, 0U) << state.fault_reason;
  RecordProperty("link_losses", static_cast<int>(state.link_losses));
}

TEST_F(GatewayLoopback, HeartbeatStallStopsTheCraneAndLatchesTheFault) {
  start_gateway();
  take_control();
  drive({0.3, 0.0, 0.0}, 1500ms);
  ASSERT_GT(plc->snapshot().velocity_command_mps.x(), 0.25);

  const auto last_heartbeat = runner->pause();
  ASSERT_TRUE(plc->wait_until(
      [](const plc::PlcSnapshot& s) { return s.status.flags.heartbeat_fault; }, 1s));
  const auto fault_seen = Clock::now();
  ASSERT_TRUE(plc->wait_until(
      [](const plc::PlcSnapshot& s) {
        return s.velocity_command_mps.isZero() && !s.status.flags.moving;
      },
      1s));
  const auto standstill = Clock::now();
  const auto config = plc_config(0).program;
  const auto ms = [](auto d) { return std::chrono::duration<double, std::milli>(d).count(); };
  RecordProperty("fault_after_ms", std::to_string(ms(fault_seen - last_heartbeat)));
  RecordProperty("standstill_after_ms", std::to_string(ms(standstill - last_heartbeat)));
  // The PLC starts the quick stop within the heartbeat timeout (<= 250 ms) of the last heartbeat
  // and reaches standstill within v / quick-stop deceleration after that.
  EXPECT_LE(fault_seen - last_heartbeat, 250ms);
  EXPECT_GE(fault_seen - last_heartbeat, config.heartbeat_timeout);
  const auto braking = std::chrono::duration<double>(0.3 / config.quick_stop_decel_mps2.x());
  EXPECT_LE(standstill - last_heartbeat,
            250ms + std::chrono::duration_cast<std::chrono::nanoseconds>(braking) + 30ms);
  auto snapshot = plc->snapshot();
  EXPECT_EQ(snapshot.status.fault_code, crane::FaultCode::kHeartbeatTimeout);
  EXPECT_FALSE(snapshot.status.flags.enabled);

  // The gateway comes back: it sees the latched fault, and the crane stays put until reset.
  runner->resume();
  ASSERT_TRUE(runner->wait_for(
      [](const GatewayState& s) { return s.fault == GatewayFault::kPlcFault; }, 2s));
  EXPECT_EQ(gateway->state().fault_reason, "PLC fault heartbeat_timeout");
  const double x = axes.read().position_m.x();
  drive({0.3, 0.0, 0.0}, 300ms);
  EXPECT_DOUBLE_EQ(axes.read().position_m.x(), x);

  gateway->request_reset();
  take_control();
  drive({0.3, 0.0, 0.0}, 500ms);
  EXPECT_GT(axes.read().position_m.x(), x + 0.01);
  EXPECT_EQ(gateway->state().fault, GatewayFault::kNone);
}

TEST_F(GatewayLoopback, PlcKilledIsReportedAtOnceAndReconnectWritesZero) {
  start_gateway(2s);  // a long command timeout: only the reconnect rule can stop a replay
  take_control();
  drive({0.2, 0.0, 0.0}, 500ms);
  ASSERT_GT(plc->snapshot().command->velocity_mps.x(), 0.19);
  const auto last_command = std::chrono::system_clock::now();
  send({0.2, 0.0, 0.0});
  ASSERT_TRUE(runner->wait_cycles(1));

  const auto killed = Clock::now();
  plc.reset();  // the PLC (its program and its memory) is gone
  ASSERT_TRUE(runner->wait_for([](const GatewayState& s) { return !s.link_up; }, 1s));
  const auto reported = Clock::now();
  EXPECT_LE(reported - killed, 200ms);
  RecordProperty(
      "fault_reported_after_ms",
      std::to_string(std::chrono::duration<double, std::milli>(reported - killed).count()));
  const GatewayState down = gateway->state();
  EXPECT_EQ(down.fault, GatewayFault::kLinkDown);
  EXPECT_FALSE(down.fault_reason.empty());
  EXPECT_TRUE(down.setpoint_mps.isZero());
  EXPECT_GE(down.link_losses, 1U);

  start_plc(port);  // a new PLC on the same port
  ASSERT_TRUE(runner->wait_for(
      [](const GatewayState& s) { return s.link_up && s.external_control_granted; }, 5s));
  // Granted, and the last command is still younger than its timeout: it must not come back.
  for (int i = 0; i < 5; ++i) {
    ASSERT_TRUE(runner->wait_cycles(1));
    ASSERT_LT(std::chrono::system_clock::now() - last_command, 2s);
    const auto snapshot = plc->snapshot();
    ASSERT_TRUE(snapshot.command.has_value());
    EXPECT_TRUE(snapshot.command->velocity_mps.isZero()) << snapshot.command->velocity_mps;
    EXPECT_TRUE(snapshot.command->control.enable);
    EXPECT_TRUE(gateway->state().setpoint_mps.isZero());
  }
  EXPECT_GE(gateway->state().connects, 2U);

  // A command sent after the reconnect moves the crane again.
  const double x = axes.read().position_m.x();
  drive({0.2, 0.0, 0.0}, 400ms);
  EXPECT_GT(axes.read().position_m.x(), x + 0.01);
}

TEST_F(GatewayLoopback, EmergencyStopHoldsUntilReset) {
  start_gateway();
  take_control();
  drive({0.0, 0.3, 0.0}, 1200ms);
  plc->set_emergency_stop(true);
  ASSERT_TRUE(plc->wait_until(
      [](const plc::PlcSnapshot& s) {
        return s.status.flags.emergency_stop && s.velocity_command_mps.isZero() &&
               !s.status.flags.moving;
      },
      1s));
  ASSERT_TRUE(runner->wait_for(
      [](const GatewayState& s) { return s.fault == GatewayFault::kPlcFault; }, 1s));
  EXPECT_EQ(gateway->state().fault_reason, "PLC fault emergency_stop");

  const double y = axes.read().position_m.y();
  drive({0.0, 0.3, 0.0}, 300ms);
  EXPECT_DOUBLE_EQ(axes.read().position_m.y(), y);
  gateway->request_reset();  // refused while pressed
  drive({0.0, 0.3, 0.0}, 300ms);
  EXPECT_DOUBLE_EQ(axes.read().position_m.y(), y);
  EXPECT_TRUE(plc->snapshot().status.flags.emergency_stop);

  plc->set_emergency_stop(false);  // released, but latched
  drive({0.0, 0.3, 0.0}, 300ms);
  EXPECT_DOUBLE_EQ(axes.read().position_m.y(), y);

  gateway->request_reset();
  take_control();
  drive({0.0, 0.3, 0.0}, 500ms);
  EXPECT_GT(axes.read().position_m.y(), y + 0.01);
}

TEST_F(GatewayLoopback, ImplausiblePlcStateIsRejectedWithAReason) {
  start_gateway();
  take_control();
  axes.set_load_kg(50000);  // beyond what the hoist can weigh
  ASSERT_TRUE(runner->wait_for(
      [](const GatewayState& s) { return s.fault == GatewayFault::kImplausibleState; }, 2s));
  const GatewayState state = gateway->state();
  EXPECT_NE(state.fault_reason.find("register 29 (load mass)"), std::string::npos)
      << state.fault_reason;
  EXPECT_FALSE(state.external_control_granted);
  send({0.2, 0.0, 0.0});
  ASSERT_TRUE(runner->wait_cycles(2));
  EXPECT_TRUE(plc->snapshot().command->velocity_mps.isZero());
  EXPECT_EQ(runner->last_report().outcome, CycleOutcome::kImplausibleState);
}

TEST_F(GatewayLoopback, RefusesAPlcWithOtherLimitsAndWritesNothing) {
  CraneGatewayConfig config = gateway_config();
  config.logic.plausibility.limits.position_max_m.x() = 20.0;
  gateway = std::make_unique<CraneGateway>(config);
  const CycleReport report = gateway->cycle();
  EXPECT_EQ(report.outcome, CycleOutcome::kMapMismatch);
  EXPECT_NE(report.reason.find("bridge range"), std::string::npos) << report.reason;
  EXPECT_EQ(gateway->state().fault, GatewayFault::kPlcMapMismatch);
  ASSERT_TRUE(plc->wait_until([](const plc::PlcSnapshot& s) { return s.cycles > 2; }, 1s));
  EXPECT_EQ(plc->snapshot().command_registers, crane::CommandRegisters{});
}

TEST_F(GatewayLoopback, ReleaseHandsTheCraneBackWithoutAFault) {
  start_gateway();
  take_control();
  runner.reset();
  gateway->release();
  ASSERT_TRUE(
      plc->wait_until([](const plc::PlcSnapshot& s) { return !s.status.flags.enabled; }, 1s));
  // Nobody holds the crane, so the silent heartbeat is no fault.
  const auto cycles = plc->snapshot().cycles;
  ASSERT_TRUE(
      plc->wait_until([&](const plc::PlcSnapshot& s) { return s.cycles > cycles + 100; }, 2s));
  EXPECT_FALSE(plc->snapshot().status.flags.fault);
}

TEST(GatewayReconnect, BacksOffExponentiallyOnAFakeClock) {
  // A port nobody listens on: bind an ephemeral one, then free it.
  std::uint16_t closed_port = 0;
  {
    plc::ModbusServerConfig c;
    c.port = 0;
    plc::ModbusRegisterServer probe(c, 1, 0, 1);
    probe.start();
    closed_port = probe.port();
  }
  SteadyTime now = SteadyTime(std::chrono::seconds(100));
  GatewayClocks clocks;
  clocks.steady = [&now] { return now; };
  CraneGatewayConfig config;
  config.plc_port = closed_port;
  config.logic.plausibility.limits = reference_limits();
  config.reconnect_backoff_min = 20ms;
  config.reconnect_backoff_max = 80ms;
  CraneGateway gateway(config, clocks);

  std::vector<std::chrono::milliseconds> attempts;
  const SteadyTime start = now;
  for (int ms = 0; ms <= 400; ++ms) {
    now = start + std::chrono::milliseconds(ms);
    const CycleReport report = gateway.cycle();
    if (report.outcome == CycleOutcome::kConnectFailed) {
      attempts.push_back(std::chrono::milliseconds(ms));
      EXPECT_NE(report.reason.find("connect to 127.0.0.1:"), std::string::npos) << report.reason;
    } else {
      ASSERT_EQ(report.outcome, CycleOutcome::kWaitingToReconnect);
    }
  }
  const std::vector<std::chrono::milliseconds> expected{0ms,   20ms,  60ms, 140ms,
                                                        220ms, 300ms, 380ms};
  EXPECT_EQ(attempts, expected);
  EXPECT_EQ(gateway.state().fault, GatewayFault::kLinkDown);
  EXPECT_FALSE(gateway.state().link_up);
}

TEST(GatewayConfig, RejectsUnusableSettings) {
  CraneGatewayConfig config;
  config.logic.plausibility.limits = reference_limits();
  EXPECT_NO_THROW(validate(config));
  auto bad = config;
  bad.plc_host.clear();
  EXPECT_THROW(validate(bad), GatewayConfigError);
  bad = config;
  bad.response_timeout = 0ms;
  EXPECT_THROW(validate(bad), GatewayConfigError);
  bad = config;
  bad.reconnect_backoff_max = 1ms;
  EXPECT_THROW(validate(bad), GatewayConfigError);
  bad = config;
  bad.logic.command_timeout = 5ms;  // shorter than a cycle
  EXPECT_THROW(validate(bad), GatewayConfigError);
  bad = config;
  bad.logic.plausibility.limits.max_speed_mps.x() = -1.0;
  EXPECT_THROW(CraneGateway{bad}, GatewayConfigError);
}

}  // namespace
}  // namespace rigger::crane_gateway
