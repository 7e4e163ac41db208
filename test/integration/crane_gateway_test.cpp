// The crane gateway and the simulated cell's PLC emulator as real processes, Modbus TCP on loopback,
// DDS on a private domain (acceptance): move to a commanded position, heartbeat stall,
// PLC link cut, e-stop. The crane's true state comes from a second path, the simulator's status
// (rigger/sim/status), which also carries the PLC's registers.
#include <signal.h>

#include <cmath>
#include <fstream>
#include <iostream>

#include <gtest/gtest.h>

#include "cell_sim_test_support.hpp"
#include "rigger/safety/safe_stop.hpp"
#include "rigger/crane_protocol/register_map.hpp"
#include "rigger/protocol/crane.hpp"

namespace rigger::testing {
namespace {

using namespace std::chrono_literals;

/// What the tests read of rigger/crane/state.
struct CraneView {
  WallTime stamp{};
  bool link_ok = false;
  bool fault = false;
  bool external_control = false;
  bool estop = false;
  std::uint16_t fault_code = 0;
  std::string fault_text;
  Eigen::Vector3d position_m = Eigen::Vector3d::Zero();
  Eigen::Vector3d velocity_mps = Eigen::Vector3d::Zero();
};

class CraneGatewayTest : public MultiProcessTest {
 protected:
  void SetUp() override {
    port_ = free_tcp_port();
    sim_ = std::make_unique<SimChannel>(cell_);
    state_ = std::make_unique<dds::Reader<rigger_crane_CraneState>>(cell_.participant(), protocol::crane::kState);
    cell_.loop().on_data(*state_, [this] {
      state_->take([this](const rigger_crane_CraneState& s, const dds_sample_info_t&) {
        CraneView v;
        v.stamp = dds::to_domain(s.header.stamp);
        v.link_ok = s.link_ok;
        v.fault = s.fault;
        v.external_control = s.external_control;
        v.estop = s.estop;
        v.fault_code = s.fault_code;
        v.fault_text = dds::to_string(s.fault_text);
        v.position_m = Eigen::Vector3d(s.position_m[0], s.position_m[1], s.position_m[2]);
        v.velocity_mps = Eigen::Vector3d(s.velocity_mps[0], s.velocity_mps[1], s.velocity_mps[2]);
        crane_.push_back(v);
      });
    });
    commands_ = std::make_unique<dds::Writer<rigger_crane_CraneVelocityCommand>>(cell_.participant(),
                                                                                 protocol::crane::kCmdVelocity);
    control_ = std::make_unique<dds::Writer<rigger_crane_CraneControl>>(cell_.participant(), protocol::crane::kControl);
    // The velocity stream, as the admittance controller sends it: 50 Hz, fresh stamps, growing seq.
    cell_.loop().every(20ms, [this] {
      if (velocity_) send_velocity(*velocity_, 0.1);
    });
  }

  /// Starts cell_sim (shipped configuration) and the gateway (shipped or `gateway_config`).
  void start(const std::string& gateway_config = repo_file("deploy/config/crane_gateway.json")) {
    const std::string port = std::to_string(port_);
    cell_.start("cell_sim", "cell_sim", {"--config", repo_file("deploy/config/cell_sim.json"), "--plc-port", port});
    ASSERT_TRUE(cell_.wait_ready({"cell_sim"}, 20s));
    cell_.start("crane_gateway", "crane_gateway", {"--config", gateway_config, "--plc-port", port});
    ASSERT_TRUE(cell_.wait_ready({"crane_gateway"}, 20s));
    ASSERT_TRUE(control_->wait_for_readers(1, 5s));
    ASSERT_TRUE(commands_->wait_for_readers(1, 5s));
    ASSERT_TRUE(cell_.wait_until([&] { return !crane_.empty() && crane_.back().link_ok && sim_->has_status(); }, 10s))
        << "the gateway did not connect to the PLC emulator on port " << port_;
  }

  void send_control(rigger_crane_CraneControlKind kind) {
    rigger_crane_CraneControl c{};
    c.header.stamp = dds::wire_now();
    c.seq = ++control_seq_;
    c.kind = kind;
    c.source = const_cast<char*>("integration-test");
    control_->write(c);
  }

  void send_velocity(const Eigen::Vector3d& v, double timeout_s, WallTime stamp = std::chrono::system_clock::now()) {
    rigger_crane_CraneVelocityCommand c{};
    c.header.stamp = dds::to_wire(stamp);
    c.seq = ++command_seq_;
    for (int i = 0; i < 3; ++i) c.velocity_mps[i] = v[i];
    c.timeout_s = timeout_s;
    c.source = const_cast<char*>("integration-test");
    commands_->write(c);
  }

  /// Asks for external control and waits for the PLC's grant.
  void take_control() {
    send_control(rigger_crane_CRANE_REQUEST_EXTERNAL);
    ASSERT_TRUE(cell_.wait_until([&] { return crane_.back().external_control && !crane_.back().fault; }, 5s))
        << "no grant: " << crane_.back().fault_text;
  }

  /// Waits until the true crane speed (simulator) is at least `speed` on `axis`.
  bool wait_moving(int axis, double speed, std::chrono::milliseconds timeout = 5s) {
    return cell_.wait_until([&] { return sim_->latest().crane_velocity_mps[axis] >= speed; }, timeout);
  }

  /// Index of the first simulator status stamped at or after `t` with `predicate`, or -1.
  template <typename P>
  int first_status_after(WallTime t, P predicate) const {
    const auto& h = sim_->history();
    for (std::size_t i = 0; i < h.size(); ++i)
      if (h[i].stamp >= t && predicate(h[i])) return static_cast<int>(i);
    return -1;
  }

  std::uint16_t port_ = 0;
  std::unique_ptr<SimChannel> sim_;
  std::unique_ptr<dds::Reader<rigger_crane_CraneState>> state_;
  std::unique_ptr<dds::Writer<rigger_crane_CraneVelocityCommand>> commands_;
  std::unique_ptr<dds::Writer<rigger_crane_CraneControl>> control_;
  std::vector<CraneView> crane_;
  std::optional<Eigen::Vector3d> velocity_;
  std::uint64_t command_seq_ = 0;
  std::uint64_t control_seq_ = 0;
};

constexpr double kStandstillMps = 0.005;  // the PLC's "moving" threshold

TEST_F(CraneGatewayTest, MovesTheCraneToACommandedPosition) {
  start();
  take_control();
  const Eigen::Vector3d start_m = crane_.back().position_m;
  // x away from the robot, y along the rails, the hook up: every axis moves.
  const Eigen::Vector3d target = start_m + Eigen::Vector3d(0.40, -0.30, 0.15);
  const Eigen::Vector3d max_speed(0.2, 0.2, 0.1);
  const auto t0 = std::chrono::steady_clock::now();
  // A P-controller on the gateway's reported position: v = 1/s * error, limited.
  const auto controller = cell_.loop().every(20ms, [&] {
    const Eigen::Vector3d error = target - crane_.back().position_m;
    velocity_ = (1.0 * error).cwiseMax(-max_speed).cwiseMin(max_speed);
  });
  const bool reached = cell_.wait_until(
      [&] {
        const CraneView& c = crane_.back();
        return (target - c.position_m).cwiseAbs().maxCoeff() < 0.005 && c.velocity_mps.cwiseAbs().maxCoeff() < 0.01;
      },
      20s);
  const double took_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  cell_.loop().cancel(controller);
  velocity_.reset();
  std::cout << "crane moved by (0.40, -0.30, 0.15) m in " << took_s
            << " s; final error (mm): " << 1000.0 * (target - crane_.back().position_m).transpose() << "\n";
  ASSERT_TRUE(reached) << "position " << crane_.back().position_m.transpose() << " target " << target.transpose();
  // The gateway's view agrees with the simulator's truth (register resolution 1 mm, samples apart in time).
  EXPECT_LT((sim_->latest().crane_position_m - crane_.back().position_m).cwiseAbs().maxCoeff(), 0.005);
  EXPECT_EQ(crane_.back().fault_text, "");
}

TEST_F(CraneGatewayTest, HeartbeatStallStopsTheCraneAndLatchesTheFault) {
  start();
  take_control();
  const double speed = 0.2;
  velocity_ = Eigen::Vector3d(speed, 0.0, 0.0);
  ASSERT_TRUE(wait_moving(0, speed - 0.01)) << "the crane did not reach " << speed << " m/s";

  const WallTime stalled = std::chrono::system_clock::now();
  ASSERT_TRUE(cell_.process("crane_gateway").signal(SIGSTOP));
  const auto heartbeat_fault = [](const SimStatusView& s) {
    return (s.plc_status_word & crane::status_bit::kHeartbeatFault) != 0 &&
           s.plc_fault_code == static_cast<std::uint16_t>(crane::FaultCode::kHeartbeatTimeout);
  };
  const auto standstill = [](const SimStatusView& s) { return s.crane_velocity_mps.norm() < kStandstillMps; };
  const bool stopped = cell_.wait_until(
      [&] { return first_status_after(stalled, heartbeat_fault) >= 0 && first_status_after(stalled, standstill) >= 0; },
      3s);
  cell_.process("crane_gateway").signal(SIGCONT);
  ASSERT_TRUE(stopped) << "latest: fault code " << sim_->latest().plc_fault_code << " speed "
                       << sim_->latest().crane_velocity_mps.norm();
  const double fault_ms = ms_between(stalled, sim_->history()[first_status_after(stalled, heartbeat_fault)].stamp);
  const double stop_ms = ms_between(stalled, sim_->history()[first_status_after(stalled, standstill)].stamp);
  // The PLC's configuration (deploy/config/cell_sim.json): heartbeat timeout 150 ms, quick stop 2.5 m/s^2.
  const double quick_stop_ms = 1000.0 * speed / 2.5;
  std::cout << "gateway SIGSTOPped at " << speed << " m/s: heartbeat fault latched after " << fault_ms
            << " ms, crane at standstill (< 5 mm/s) after " << stop_ms << " ms (quick stop alone: " << quick_stop_ms
            << " ms)\n";
  RecordProperty("heartbeat_fault_ms", static_cast<int>(fault_ms));
  RecordProperty("standstill_ms", static_cast<int>(stop_ms));
  // The watchdog fires at most one timeout (150 ms) after the last heartbeat, which the gateway wrote
  // before the stall; the quick stop then takes v / a. Statuses come every 10 ms.
  EXPECT_LE(fault_ms, 250.0);
  EXPECT_LE(stop_ms, 250.0 + quick_stop_ms);
  // Resumed, the gateway reads the latched fault and reports it.
  EXPECT_TRUE(cell_.wait_until(
      [&] {
        return crane_.back().fault &&
               crane_.back().fault_code == static_cast<std::uint16_t>(crane::FaultCode::kHeartbeatTimeout);
      },
      3s))
      << crane_.back().fault_text;
  // The fault holds: no motion until a reset, even with the stream still running.
  EXPECT_LT(sim_->latest().crane_velocity_mps.norm(), kStandstillMps);
}

TEST_F(CraneGatewayTest, PlcLinkCutIsPublishedAtOnceAndTheOldSetpointIsNeverReplayed) {
  // A long command timeout, so that the old command would still be "fresh" after the reconnect if
  // the gateway replayed it.
  const std::string config = cell_.log_dir() + "/crane_gateway.json";
  std::ofstream(config) << R"({"cell_file": ")" << repo_file("deploy/cell/simulated_cell.json")
                        << R"(", "command_timeout_ms": 6000})";
  start(config);
  take_control();
  send_velocity({0.1, 0.0, 0.0}, 6.0);  // one command, held by the gateway for 6 s
  const WallTime commanded = std::chrono::system_clock::now();
  ASSERT_TRUE(wait_moving(0, 0.09));

  const WallTime cut = std::chrono::system_clock::now();
  const auto ack = sim_->send(rigger_sim_SIM_PLC_LINK, false);
  ASSERT_TRUE(ack && ack->first) << (ack ? ack->second : "no answer");
  const auto link_lost = [&] {
    for (const auto& c : crane_)
      if (c.stamp >= cut && !c.link_ok && c.fault) return true;
    return false;
  };
  ASSERT_TRUE(cell_.wait_until(link_lost, 3s));
  WallTime published{};
  for (const auto& c : crane_) {
    if (c.stamp >= cut && !c.link_ok) {
      published = c.stamp;
      break;
    }
  }
  const double fault_ms = ms_between(cut, published);
  std::cout << "PLC link cut: gateway published link_down after " << fault_ms << " ms (\"" << crane_.back().fault_text
            << "\")\n";
  RecordProperty("link_down_ms", static_cast<int>(fault_ms));
  EXPECT_LE(fault_ms, 200.0);

  // Keep the link down longer than the PLC's heartbeat timeout (150 ms): its watchdog stops the crane
  // and latches the fault, as a cut cable does to a real crane.
  cell_.wait_until([] { return false; }, 300ms);
  const auto up = sim_->send(rigger_sim_SIM_PLC_LINK, true);
  ASSERT_TRUE(up && up->first) << (up ? up->second : "no answer");
  ASSERT_TRUE(cell_.wait_until([&] { return crane_.back().link_ok; }, 5s)) << crane_.back().fault_text;
  EXPECT_EQ(sim_->latest().plc_fault_code, static_cast<std::uint16_t>(crane::FaultCode::kHeartbeatTimeout));
  send_control(rigger_crane_CRANE_RESET);
  ASSERT_TRUE(cell_.wait_until([&] { return crane_.back().external_control && !crane_.back().fault; }, 5s))
      << crane_.back().fault_text;
  // Granted again, with the old command (stamped before the reconnect) well within its 6 s: the
  // gateway must write zero setpoints, and the crane stays still.
  const WallTime granted = std::chrono::system_clock::now();
  ASSERT_LT(ms_between(commanded, granted), 5000.0) << "too slow to test the replay";
  cell_.wait_until([] { return false; }, 500ms);
  int samples = 0;
  for (const auto& s : sim_->history()) {
    if (s.stamp < granted) continue;
    ++samples;
    EXPECT_EQ(s.plc_setpoint_mps, Eigen::Vector3d::Zero()) << "old setpoint replayed";
    EXPECT_LT(s.crane_velocity_mps.norm(), kStandstillMps);
  }
  EXPECT_GT(samples, 20);
  // A fresh command moves it.
  send_velocity({0.1, 0.0, 0.0}, 6.0);
  EXPECT_TRUE(cell_.wait_until([&] { return sim_->latest().plc_setpoint_mps.x() > 0.09; }, 2s));
  EXPECT_TRUE(wait_moving(0, 0.05));
  send_velocity({0.0, 0.0, 0.0}, 6.0);
}

TEST_F(CraneGatewayTest, EmergencyStopHoldsTheCraneUntilReset) {
  start();
  take_control();
  velocity_ = Eigen::Vector3d(0.15, 0.0, 0.0);
  ASSERT_TRUE(wait_moving(0, 0.14));
  const WallTime pressed = std::chrono::system_clock::now();
  const auto ack = sim_->send(rigger_sim_SIM_ESTOP, true);
  ASSERT_TRUE(ack && ack->first);
  ASSERT_TRUE(cell_.wait_until([&] { return sim_->latest().crane_velocity_mps.norm() < kStandstillMps; }, 2s));
  std::cout << "e-stop: standstill " << ms_between(pressed, sim_->latest().stamp) << " ms after the press\n";
  ASSERT_TRUE(cell_.wait_until([&] { return crane_.back().estop && crane_.back().fault; }, 2s));
  EXPECT_FALSE(crane_.back().external_control);

  // Released, with the velocity stream still running: the latched fault keeps the crane still.
  const auto released = sim_->send(rigger_sim_SIM_ESTOP, false);
  ASSERT_TRUE(released && released->first);
  const Eigen::Vector3d held_at = sim_->latest().crane_position_m;
  const WallTime after_release = std::chrono::system_clock::now();
  cell_.wait_until([] { return false; }, 1s);
  for (const auto& s : sim_->history()) {
    if (s.stamp < after_release) continue;
    EXPECT_LT(s.crane_velocity_mps.norm(), kStandstillMps);
    EXPECT_LT((s.crane_position_m - held_at).norm(), 0.003);
    EXPECT_EQ(s.plc_fault_code, static_cast<std::uint16_t>(crane::FaultCode::kEmergencyStop));
  }
  // Reset: the fault clears, the grant returns and the running stream moves the crane again.
  send_control(rigger_crane_CRANE_RESET);
  EXPECT_TRUE(wait_moving(0, 0.1, 5s)) << crane_.back().fault_text;
  velocity_.reset();
}

// `riggerctl crane reset`, the production way to acknowledge a latched PLC fault: with no gateway it says
// so; while the fault's cause is there (the e-stop still pressed) it says the fault stays and exits 1; once
// the cause is gone it clears the fault, and the gateway's log names who reset it.
TEST_F(CraneGatewayTest, RiggerctlCraneResetClearsALatchedFaultOnlyOnceItsCauseIsGone) {
  const auto alone = run_riggerctl(cell_, "reset-no-gateway", {"crane", "reset", "--timeout", "0.5"});
  EXPECT_EQ(alone.code(), 3) << alone.output;
  EXPECT_NE(alone.output.find("no crane gateway"), std::string::npos) << alone.output;

  start();
  take_control();
  const auto pressed = sim_->send(rigger_sim_SIM_ESTOP, true);
  ASSERT_TRUE(pressed && pressed->first);
  ASSERT_TRUE(cell_.wait_until([&] { return crane_.back().estop && crane_.back().fault; }, 2s));
  const auto refused = run_riggerctl(cell_, "reset-while-pressed", {"crane", "reset", "--timeout", "1.5"});
  EXPECT_EQ(refused.code(), 1) << refused.output;
  EXPECT_NE(refused.output.find("still reports fault"), std::string::npos) << refused.output;
  EXPECT_NE(refused.output.find("e-stop latched"), std::string::npos) << refused.output;
  EXPECT_TRUE(crane_.back().fault);

  const auto released = sim_->send(rigger_sim_SIM_ESTOP, false);
  ASSERT_TRUE(released && released->first);
  EXPECT_TRUE(crane_.back().fault) << "the PLC latches the fault until a reset";
  const auto reset = run_riggerctl(cell_, "reset", {"crane", "reset"});
  EXPECT_EQ(reset.code(), 0) << reset.output;
  EXPECT_NE(reset.output.find("crane reset by riggerctl:"), std::string::npos) << reset.output;
  EXPECT_NE(reset.output.find("no fault (was: fault"), std::string::npos) << reset.output;
  ASSERT_TRUE(cell_.wait_until([&] { return !crane_.back().fault; }, 2s)) << crane_.back().fault_text;
  const std::string gateway_log = cell_.process("crane_gateway").log();
  EXPECT_NE(gateway_log.find("crane control kind=reset seq=1 source=riggerctl:"), std::string::npos) << gateway_log;
}

// A software safe stop of the crane (rigger/safety/stop): the gateway zeroes its setpoint at once,
// refuses the velocity stream while the stop is in force (the crane stays still), says so in its state,
// and follows fresh commands again after the reset.
TEST_F(CraneGatewayTest, SafeStopHoldsTheCraneUntilItsReset) {
  start();
  safety::SafeStopWriter stops(cell_.participant());
  ASSERT_TRUE(stops.writer().wait_for_readers(1, 5s));
  take_control();
  velocity_ = Eigen::Vector3d(0.1, 0.0, 0.0);
  ASSERT_TRUE(wait_moving(0, 0.09));

  const WallTime stop_at = std::chrono::system_clock::now();
  ASSERT_EQ(stops.command("crane", true, "integration-test", "stop the crane"), DDS_RETCODE_OK);
  ASSERT_TRUE(cell_.wait_until([&] { return std::abs(sim_->latest().crane_velocity_mps.x()) < 0.001; }, 3s))
      << "the crane still moves at " << sim_->latest().crane_velocity_mps.x() << " m/s";
  const int zero = first_status_after(stop_at, [](const SimStatusView& v) { return v.plc_setpoint_mps.norm() == 0.0; });
  ASSERT_GE(zero, 0);
  const int still = first_status_after(stop_at, [](const SimStatusView& v) { return std::abs(v.crane_velocity_mps.x()) < 0.001; });
  std::cout << "safe stop: PLC setpoint zero after " << ms_between(stop_at, sim_->history()[zero].stamp)
            << " ms, crane below 1 mm/s after " << ms_between(stop_at, sim_->history()[still].stamp) << " ms\n";
  EXPECT_LT(ms_between(stop_at, sim_->history()[zero].stamp), 200.0) << "the setpoint outlived the stop";
  ASSERT_TRUE(cell_.wait_until([&] { return crane_.back().fault; }, 2s));
  EXPECT_EQ(crane_.back().fault_text.rfind("SAFE_STOP: integration-test: stop the crane", 0), 0u)
      << crane_.back().fault_text;
  // The stream goes on for 1 s: none of it is applied.
  const Eigen::Vector3d held = sim_->latest().crane_position_m;
  cell_.wait_until([] { return false; }, 1s);
  EXPECT_LT((sim_->latest().crane_position_m - held).norm(), 0.002) << "the crane moved while stopped";

  ASSERT_EQ(stops.command("crane", false, "integration-test", "reset"), DDS_RETCODE_OK);
  EXPECT_TRUE(wait_moving(0, 0.05)) << "fresh commands after the reset did not move the crane";
  velocity_.reset();
}

TEST_F(CraneGatewayTest, BadConfigurationExitsWithCode2NamingTheKey) {
  expect_refused_configuration(cell_, "crane_gateway", R"({"cycle_rate_hz": 5000})", "/cycle_rate_hz");
  expect_clean_exit_ = false;
}

}  // namespace
}  // namespace rigger::testing
