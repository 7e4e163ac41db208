#pragma once
// The crane PLC emulator: the PLC program, the crane register map served over Modbus TCP, and
// the crane drives (CraneAxesIo), tied together as a real crane PLC would be.

#include <Eigen/Core>
#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <functional>
#include <mutex>
#include <optional>
#include <thread>

#include "rigger/crane_protocol/register_map.hpp"
#include "rigger/plc/crane_axes_io.hpp"
#include "rigger/plc/modbus_register_server.hpp"
#include "rigger/plc/plc_program.hpp"

namespace rigger::plc {

/// Configuration of the emulator.
struct PlcEmulatorConfig {
  PlcProgramConfig program;
  ModbusServerConfig server;
};

/// What the PLC last saw and did, for tests and diagnostics.
struct PlcSnapshot {
  crane::CommandRegisters command_registers{};  ///< command block as the program last read it
  std::optional<crane::CraneCommand> command;   ///< its decoding; nothing if invalid
  crane::CraneStatus status;                    ///< status block as last written
  Eigen::Vector3d velocity_command_mps = Eigen::Vector3d::Zero();  ///< to the drives
  std::chrono::nanoseconds program_time{0};
  std::uint64_t cycles = 0;
  bool emergency_stop_pressed = false;
  ModbusServerStats server;
};

/// The emulated crane PLC. Each step() reads the drives, reads the command block, runs the PLC
/// program, writes the status block and commands the drives. Either the owner calls step() from
/// its physics loop, or start_cycle_thread() runs it on a thread of its own.
/// Thread-safe; `axes` must outlive the emulator and is called from the stepping thread only.
class PlcEmulator {
 public:
  /// Writes the limits block and runs a first scan (step with dt = 0, which reads `axes` and
  /// commands them to rest). Throws PlcConfigError. Starts neither the server nor a thread.
  PlcEmulator(PlcEmulatorConfig config, CraneAxesIo& axes);
  ~PlcEmulator();
  PlcEmulator(const PlcEmulator&) = delete;
  PlcEmulator& operator=(const PlcEmulator&) = delete;

  /// Starts serving the register map. Throws crane::ModbusError (e.g. the port is in use).
  void start_server();
  /// Closes every connection and the listening socket; the PLC program keeps running.
  void stop_server();
  /// The bound port (resolves a configured port 0); 0 while the server is stopped.
  std::uint16_t port() const { return server_.port(); }

  /// Runs one PLC cycle of length `dt`.
  void step(std::chrono::nanoseconds dt);

  /// Steps every `period` on a thread of its own with the measured elapsed time as dt, calling
  /// `before_step(dt)` first (e.g. to advance a kinematic crane). No effect if already running.
  void start_cycle_thread(std::chrono::nanoseconds period,
                          std::function<void(std::chrono::nanoseconds)> before_step = {});
  /// Stops and joins the cycle thread. Idempotent.
  void stop_cycle_thread();

  /// The e-stop input, as a button on the crane would set it; acts on the next cycle.
  void set_emergency_stop(bool pressed);

  PlcSnapshot snapshot() const;
  /// Waits until `predicate(snapshot)` holds, re-checking after every cycle; false on timeout.
  bool wait_until(const std::function<bool(const PlcSnapshot&)>& predicate,
                  std::chrono::nanoseconds timeout) const;

 private:
  void cycle_loop(std::chrono::nanoseconds period,
                  const std::function<void(std::chrono::nanoseconds)>& before_step);

  CraneAxesIo& axes_;
  ModbusRegisterServer server_;

  mutable std::mutex mutex_;  // guards program_ and snapshot_
  mutable std::condition_variable cycled_;
  PlcProgram program_;
  PlcSnapshot snapshot_;

  std::mutex thread_mutex_;
  std::condition_variable thread_wake_;
  bool thread_stop_ = false;
  std::thread thread_;
};

}  // namespace rigger::plc
