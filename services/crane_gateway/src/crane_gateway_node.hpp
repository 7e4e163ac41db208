#pragma once
/// @file
/// The crane gateway's DDS plumbing (docs/crane-modbus.md, docs/cell-sim.md): velocity commands and
/// control requests in, the crane's state out, CraneGateway's Modbus cycle on a work thread of its
/// own at the configured rate (default 50 Hz).
///
/// Axis convention on every topic and register: x bridge, y trolley, z hoist = hook height above the
/// crane frame, up positive (idl/crane.idl). A controller that works with the hoist positive down
/// (rope length) must negate z before publishing rigger/crane/cmd_velocity.
///
/// rigger/crane/state is published once per cycle (at most the cycle rate, 50 Hz by default), also
/// when nothing changed: its stamp then tells readers that the gateway is alive, and a link loss is
/// published in the cycle that detects it.

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include <CLI/CLI.hpp>

#include "crane_gateway.hpp"
#include "rigger/base/settings.hpp"
#include "rigger/crane_gateway/settings.hpp"
#include "rigger/dds/pubsub.hpp"
#include "rigger/safety/safe_stop.hpp"
#include "rigger/service/service.hpp"

namespace rigger::crane_gateway {

/// Command-line overrides of the configuration (tests point the gateway at their PLC emulator).
struct CommandLine {
  std::optional<std::string> plc_host;
  std::optional<std::uint16_t> plc_port;
  void add_to(CLI::App& app);
};

/// The crane gateway's configuration: the cycle's, and where the crane's limits come from.
struct GatewaySettings {
  CraneGatewayConfig gateway;
  std::filesystem::path cell_file;
  std::string crane_id;
};

/// Reads gateway_settings() from deploy/config/crane_gateway.json; the crane's limits come from the cell
/// file's crane entity. Does not call finish(). @throws ConfigError.
CraneGatewayConfig read_gateway_config(const Config& config);

/// The CraneState a gateway state becomes on the wire, in domain terms (for to_wire and its test).
struct CraneStateReport {
  rigger_crane_CraneMode mode = rigger_crane_CRANE_STOPPED;
  bool link_ok = false;
  bool fault = true;
  std::string fault_text;
};
/// Mode, link and fault summary of `state` (the rest of CraneState copies the PLC's status block).
CraneStateReport summarize(const GatewayState& state);

class CraneGatewayNode : public service::Node {
 public:
  /// @throws ConfigError, DdsError.
  CraneGatewayNode(service::ServiceContext& ctx, const CommandLine& command_line);
  /// Stops the cycle and releases the crane (enable and external control off, zero setpoints).
  ~CraneGatewayNode() override;

 private:
  void on_command();
  void on_control();
  void work();
  void publish(const GatewayState& state, WallTime now);
  void log_cycle(const CycleReport& report, const GatewayState& state);

  service::ServiceContext& ctx_;
  CraneGatewayConfig config_;
  dds::Writer<rigger_crane_CraneState> state_;
  dds::Reader<rigger_crane_CraneVelocityCommand> commands_;
  dds::Reader<rigger_crane_CraneControl> control_;
  CraneGateway gateway_;
  std::unique_ptr<safety::SafeStopListener> safe_stop_;

  // event loop thread
  ControlRequest control_request_;
  std::uint64_t commands_refused_ = 0;
  std::chrono::steady_clock::time_point last_refusal_log_{};
  std::atomic<std::uint64_t> last_command_seq_{0};

  // work thread
  std::optional<CycleOutcome> last_outcome_;
  std::string last_reason_;
  std::chrono::steady_clock::time_point last_repeat_log_{};

  std::mutex mutex_;
  std::condition_variable wake_;
  bool stop_ = false;
  std::thread thread_;  // last: started once everything it uses exists
};

}  // namespace rigger::crane_gateway
