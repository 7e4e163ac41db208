#include "crane_gateway_node.hpp"

#include <cmath>
#include <filesystem>

#include "rigger/base/install.hpp"
#include "rigger/crane_protocol/crane_config.hpp"
#include "rigger/dds/conversions.hpp"
#include "rigger/protocol/crane.hpp"

namespace rigger::crane_gateway {
namespace {

namespace fs = std::filesystem;
using SteadyClock = std::chrono::steady_clock;

// rigger/crane/state is written every cycle: with a liveliness lease on the writer, asserted by each
// write, readers see a hung cycle thread within the lease, not only a dead process.
dds::Qos state_qos() {
  dds::Qos qos = dds::qos::state();
  dds_qset_liveliness(qos.get(), DDS_LIVELINESS_MANUAL_BY_TOPIC, DDS_MSECS(dds::kStateStreamLease.count()));
  return qos;
}

}  // namespace

void CommandLine::add_to(CLI::App& app) {
  app.add_option("--plc-host", plc_host, "PLC address (overrides plc/host)");
  app.add_option("--plc-port", plc_port, "PLC Modbus TCP port (overrides plc/port)")->check(CLI::Range(1, 65535));
}

const SettingsTable<GatewaySettings>& gateway_settings() {
  using S = GatewaySettings;
  using std::chrono::milliseconds;
  static const SettingsTable<S> table{
      path_setting<S>("cell_file", kDefaultCellFile, &S::cell_file,
                      "the cell file whose crane entity gives the crane's limits (they must match the PLC's limits "
                      "block): relative to this file, then to the data folder"),
      setting<S>("crane_id", "crane", &S::crane_id, "the crane's entity in the cell file"),
      nested("plc", setting<S>(
                        "host", "127.0.0.1", [](S& s, const std::string& v) { s.gateway.plc_host = v; },
                        "the PLC's address (a numeric one: a name is resolved at every connect); "
                        "`--plc-host` takes its place")),
      nested("plc", setting<S>(
                        "port", 1502u, {1u, 65535u},
                        [](S& s, unsigned v) { s.gateway.plc_port = static_cast<std::uint16_t>(v); },
                        "the PLC's Modbus TCP port (502 on most PLCs); `--plc-port` takes its place")),
      nested("plc", setting<S>(
                        "unit_id", 1, {0, 255}, [](S& s, int v) { s.gateway.unit_id = v; },
                        "the Modbus unit id: 0 … 247 or 255")),
      nested("plc", setting<S>(
                        "response_timeout_ms", 50, {1, 5000},
                        [](S& s, int v) { s.gateway.response_timeout = milliseconds(v); },
                        "bounds the connect and each response; a late answer drops the connection")),
      setting<S>(
          "cycle_rate_hz", 50.0, {1.0, 500.0},
          [](S& s, double hz) { s.gateway.cycle_period = milliseconds(std::max<long>(1, std::lround(1000.0 / hz))); },
          "Modbus cycles per second (the period rounded to whole milliseconds)"),
      nested("reconnect_backoff_ms",
             setting<S>(
                 "min", 20, {1, 60000}, [](S& s, int v) { s.gateway.reconnect_backoff_min = milliseconds(v); },
                 "the first reconnect after this long, doubling up to `max`")),
      nested("reconnect_backoff_ms",
             setting<S>(
                 "max", 2000, {1, 600000}, [](S& s, int v) { s.gateway.reconnect_backoff_max = milliseconds(v); },
                 "the longest wait between reconnects; not below `min`")),
      setting<S>(
          "command_timeout_ms", 100, {1, 10000}, [](S& s, int v) { s.gateway.logic.command_timeout = milliseconds(v); },
          "a velocity command drives the crane at most this long; not below the cycle period"),
      setting<S>(
          "max_command_future_ms", 50, {0, 5000},
          [](S& s, int v) { s.gateway.logic.max_command_future = milliseconds(v); },
          "how far in the future a command's stamp may be (clock skew)"),
      setting<S>(
          "plc_heartbeat_timeout_ms", 250, {10, 10000},
          [](S& s, int v) { s.gateway.logic.plc_heartbeat_timeout = milliseconds(v); },
          "the PLC's heartbeat must change within it"),
      setting<S>(
          "reset_pulse_cycles", 3, {1, 100}, [](S& s, int v) { s.gateway.logic.reset_pulse_cycles = v; },
          "cycles the fault-reset bit is held"),
      nested("plausibility", setting<S>(
                                 "position_margin_m", 0.2, {0.0, 10.0},
                                 [](S& s, double v) { s.gateway.logic.plausibility.position_margin_m = v; },
                                 "a reported position may lie this far outside the crane's travel")),
      nested("plausibility", setting<S>(
                                 "speed_factor", 1.25, {1.0, 10.0},
                                 [](S& s, double v) { s.gateway.logic.plausibility.speed_factor = v; },
                                 "a reported speed may exceed the crane's limit by this factor")),
      nested("plausibility",
             setting<S>(
                 "load_factor", 2.0, {1.0, 100.0}, [](S& s, double v) { s.gateway.logic.plausibility.load_factor = v; },
                 "a reported load may exceed the crane's rated load by this factor")),
  };
  return table;
}

CraneGatewayConfig read_gateway_config(const Config& config) {
  GatewaySettings s;
  read_into(config, gateway_settings(), s);
  try {
    s.gateway.logic.plausibility.limits = crane::load_crane_limits(s.cell_file.string(), s.crane_id);
  } catch (const crane::CraneConfigError& e) {
    config.fail(config.has("cell_file") ? "cell_file" : "", e.what());
  }
  try {
    validate(s.gateway);
  } catch (const GatewayConfigError& e) {
    config.fail("", e.what());
  }
  return s.gateway;
}

CraneStateReport summarize(const GatewayState& state) {
  CraneStateReport r;
  r.link_ok = state.link_up;
  const bool plc_fault = state.link_up && state.plc && state.plc->flags.fault;
  r.fault = state.fault != GatewayFault::kNone || plc_fault || state.safe_stop;
  if (state.safe_stop) {
    r.fault_text = "SAFE_STOP: " + state.safe_stop_reason;
  } else if (state.fault != GatewayFault::kNone) {
    r.fault_text = std::string(fault_name(state.fault)) + ": " + state.fault_reason;
  } else if (plc_fault) {
    r.fault_text = std::string(crane::fault_code_name(state.plc->fault_code));
  }
  if (state.external_control_granted) {
    r.mode = rigger_crane_CRANE_EXTERNAL;
  } else if (!state.link_up || r.fault || (state.plc && state.plc->flags.emergency_stop)) {
    r.mode = rigger_crane_CRANE_STOPPED;
  } else {
    r.mode = rigger_crane_CRANE_LOCAL;
  }
  return r;
}

CraneGatewayNode::CraneGatewayNode(service::ServiceContext& ctx, const CommandLine& command_line)
    : ctx_(ctx),
      config_([&] {
        CraneGatewayConfig c = read_gateway_config(ctx.config);
        if (command_line.plc_host) c.plc_host = *command_line.plc_host;
        if (command_line.plc_port) c.plc_port = *command_line.plc_port;
        ctx.config.finish();
        return c;
      }()),
      state_(ctx.participant, protocol::crane::kState, state_qos()),
      commands_(ctx.participant, protocol::crane::kCmdVelocity),
      control_(ctx.participant, protocol::crane::kControl),
      gateway_(config_) {
  ctx.loop.on_data(commands_, [this] { on_command(); });
  ctx.loop.on_data(control_, [this] { on_control(); });
  // A safe stop of the crane zeroes the setpoint from the next cycle on and refuses every velocity
  // command until its reset (docs/safety.md).
  safe_stop_ = std::make_unique<safety::SafeStopListener>(
      ctx.participant, ctx.loop, std::vector<std::string>{"crane"},
      [this](const std::string&, const safety::StopState& s) {
        gateway_.set_safe_stop(s.active, s.source + ": " + s.reason);
        if (s.active)
          ctx_.log->error("SAFE_STOP crane by={} reason=\"{}\": setpoint zero, velocity commands refused until reset",
                          s.source, s.reason);
        else
          ctx_.log->warn("safe stop reset crane by={} reason=\"{}\"", s.source, s.reason);
      });
  thread_ = std::thread([this] { work(); });
  ctx.log->info("crane gateway started plc={}:{} unit_id={} cycle_ms={} command_timeout_ms={}", config_.plc_host,
                config_.plc_port, config_.unit_id, config_.cycle_period.count(),
                std::chrono::duration_cast<std::chrono::milliseconds>(config_.logic.command_timeout).count());
}

CraneGatewayNode::~CraneGatewayNode() {
  {
    const std::lock_guard<std::mutex> lock(mutex_);
    stop_ = true;
  }
  wake_.notify_all();
  thread_.join();
  gateway_.release();
  publish(gateway_.state(), std::chrono::system_clock::now());
  ctx_.log->info("crane released: enable and external control off, setpoints zero");
}

void CraneGatewayNode::on_command() {
  commands_.take([this](const rigger_crane_CraneVelocityCommand& c, const dds_sample_info_t&) {
    const WallTime now = std::chrono::system_clock::now();
    VelocityCommand command;
    command.velocity_mps = {c.velocity_mps[0], c.velocity_mps[1], c.velocity_mps[2]};
    command.stamp = dds::to_domain(c.header.stamp);
    command.seq = c.seq;
    std::string refusal;
    // The command's own timeout is checked on receipt too (after a network drop DDS may deliver a burst of
    // old samples, and none of them may move the crane); the gateway's configured command timeout then
    // bounds how long an accepted command drives the crane.
    if (std::isnan(c.timeout_s) || c.timeout_s < 0.0) {
      refusal = "timeout_s must be >= 0";
    } else if (c.timeout_s > 0.0 && now - command.stamp > from_seconds(std::min(c.timeout_s, 1e6))) {
      refusal = "stale";
    } else {
      const CommandVerdict verdict = gateway_.submit_command(command);
      if (verdict == CommandVerdict::kAccepted) {
        last_command_seq_ = c.seq;
        return;
      }
      refusal = std::string(verdict_name(verdict));
    }
    ++commands_refused_;
    const auto steady_now = SteadyClock::now();
    if (steady_now - last_refusal_log_ > std::chrono::seconds(2)) {
      last_refusal_log_ = steady_now;
      ctx_.log->warn("velocity command ignored seq={} source={} reason={} refused_total={}", c.seq,
                     dds::to_string(c.source), refusal, commands_refused_);
    }
  });
}

void CraneGatewayNode::on_control() {
  control_.take([this](const rigger_crane_CraneControl& c, const dds_sample_info_t&) {
    const char* what = "unknown";
    switch (c.kind) {
      case rigger_crane_CRANE_ENABLE:
        control_request_.enable = true;
        what = "enable";
        break;
      case rigger_crane_CRANE_DISABLE:
        control_request_ = ControlRequest{};
        what = "disable";
        break;
      case rigger_crane_CRANE_RESET:
        gateway_.request_reset();
        what = "reset";
        break;
      case rigger_crane_CRANE_REQUEST_EXTERNAL:
        // External control needs the drives on: the request implies enable.
        control_request_ = ControlRequest{true, true};
        what = "request_external";
        break;
      case rigger_crane_CRANE_RELEASE_EXTERNAL:
        control_request_.external_control = false;
        what = "release_external";
        break;
      default:
        ctx_.log->warn("crane control ignored seq={} reason=unknown kind {}", c.seq, static_cast<int>(c.kind));
        return;
    }
    gateway_.set_control(control_request_);
    ctx_.log->info("crane control kind={} seq={} source={} enable={} external={}", what, c.seq,
                   dds::to_string(c.source), control_request_.enable, control_request_.external_control);
  });
}

void CraneGatewayNode::work() {
  const auto period = config_.cycle_period;
  auto next = SteadyClock::now();
  std::unique_lock<std::mutex> lock(mutex_);
  while (!stop_) {
    lock.unlock();
    const CycleReport report = gateway_.cycle();
    const GatewayState state = gateway_.state();
    publish(state, std::chrono::system_clock::now());
    log_cycle(report, state);
    lock.lock();
    next += period;
    const auto now = SteadyClock::now();
    // After a stall (a debugger, SIGSTOP) cycle on from now rather than in a burst.
    if (next < now - period) next = now;
    wake_.wait_until(lock, next, [this] { return stop_; });
  }
}

void CraneGatewayNode::log_cycle(const CycleReport& report, const GatewayState& state) {
  if (report.outcome == CycleOutcome::kWaitingToReconnect) return;
  const bool changed = !last_outcome_ || *last_outcome_ != report.outcome;
  const auto now = SteadyClock::now();
  if (!changed && (report.reason == last_reason_ || now - last_repeat_log_ < std::chrono::seconds(5))) return;
  last_outcome_ = report.outcome;
  last_reason_ = report.reason;
  last_repeat_log_ = now;
  if (report.outcome == CycleOutcome::kOk) {
    ctx_.log->info("crane link ok plc={}:{} connects={} link_losses={}", config_.plc_host, config_.plc_port,
                   state.connects, state.link_losses);
  } else {
    ctx_.log->warn("crane cycle outcome={} reason=\"{}\" link_up={} link_losses={}", outcome_name(report.outcome),
                   report.reason, state.link_up, state.link_losses);
  }
}

void CraneGatewayNode::publish(const GatewayState& state, WallTime now) {
  const CraneStateReport summary = summarize(state);
  rigger_crane_CraneState w{};
  w.header.stamp = dds::to_wire(now);
  w.header.frame_id = const_cast<char*>("crane");
  w.mode = summary.mode;
  w.link_ok = summary.link_ok;
  w.fault = summary.fault;
  w.fault_text = dds::wire_string(summary.fault_text);
  w.last_command_seq = last_command_seq_.load();
  // While the link is down, positions, velocities and load are the last values read (link_ok false).
  if (state.plc) {
    const crane::CraneStatus& plc = *state.plc;
    for (int i = 0; i < 3; ++i) {
      w.position_m[i] = plc.position_m[i];
      w.velocity_mps[i] = plc.velocity_mps[i];
    }
    w.load_mass_kg = plc.load_kg;
    w.plc_heartbeat = plc.plc_heartbeat;
    if (state.link_up) {
      w.ready = plc.flags.ready;
      w.enabled = plc.flags.enabled;
      w.external_control = state.external_control_granted;
      w.moving = plc.flags.moving;
      w.estop = plc.flags.emergency_stop;
      w.overload = plc.flags.overload;
      w.status_word = crane::encode_status_word(plc.flags);
      w.fault_code = static_cast<std::uint16_t>(plc.fault_code);
    }
  }
  state_.write(w);
}

}  // namespace rigger::crane_gateway
