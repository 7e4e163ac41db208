#pragma once
// A Modbus TCP server (libmodbus) serving a block of holding registers on its own thread.

#include <modbus/modbus.h>

#include <atomic>
#include <chrono>
#include <cstdint>
#include <functional>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "rigger/crane_protocol/modbus_context.hpp"

namespace rigger::plc {

/// Where and how the server listens.
struct ModbusServerConfig {
  std::string address = "127.0.0.1";  ///< IPv4 address to bind; "0.0.0.0" for all interfaces
  std::uint16_t port = 1502;          ///< 0: an ephemeral port (see ModbusRegisterServer::port)
  int max_clients = 4;                ///< further connections are closed at once
  /// A started request must be complete within this time, or its client is dropped.
  std::chrono::milliseconds byte_timeout{100};
};

/// Counters of the server, for tests and diagnostics.
struct ModbusServerStats {
  std::uint64_t connections_accepted = 0;
  std::uint64_t connections_refused = 0;  ///< over max_clients
  std::uint64_t requests_served = 0;
  std::uint64_t requests_rejected = 0;  ///< writes outside the writable range (exception 02)
  int clients = 0;                      ///< currently connected
};

/// Holding registers 0 .. register_count-1 served over Modbus TCP; clients may write only
/// [writable_begin, writable_begin + writable_count) and get ILLEGAL DATA ADDRESS otherwise.
///
/// The register memory outlives start()/stop(): stopping closes the sockets (the PLC's network
/// module going away) but keeps the values. Thread safety: all public methods are thread-safe;
/// with_registers() runs its function under the mutex the server thread takes to answer a
/// request, so a block read or written there is consistent.
class ModbusRegisterServer {
 public:
  /// Throws crane::ModbusError if the mapping cannot be allocated.
  ModbusRegisterServer(ModbusServerConfig config, std::uint16_t register_count,
                       std::uint16_t writable_begin, std::uint16_t writable_count);
  ~ModbusRegisterServer();
  ModbusRegisterServer(const ModbusRegisterServer&) = delete;
  ModbusRegisterServer& operator=(const ModbusRegisterServer&) = delete;

  /// Binds, listens and starts the server thread. Throws crane::ModbusError (e.g. port in use).
  /// No effect if already running.
  void start();
  /// Closes the listening and all client sockets and joins the thread. Idempotent.
  void stop();
  bool running() const { return running_.load(); }
  /// The port actually bound (resolves port 0); 0 while stopped.
  std::uint16_t port() const { return bound_port_.load(); }

  /// Runs `fn(registers, count)` with the register memory locked.
  void with_registers(const std::function<void(std::uint16_t* registers, std::size_t count)>& fn);
  ModbusServerStats stats() const;

  /// Called on the server thread after every request served (outside the register lock).
  void set_on_request(std::function<void()> on_request);

 private:
  void serve(int listen_fd);
  /// Whether the request in `query` (length `length`) writes outside the writable range.
  bool writes_outside(const std::uint8_t* query, int length) const;
  void close_clients(std::vector<int>& clients);

  ModbusServerConfig config_;
  std::uint16_t register_count_;
  std::uint16_t writable_begin_;
  std::uint16_t writable_count_;

  mutable std::mutex registers_mutex_;
  modbus_mapping_t* mapping_ = nullptr;
  crane::ModbusContextPtr context_;  // used by the server thread only while running

  mutable std::mutex stats_mutex_;
  ModbusServerStats stats_;
  std::function<void()> on_request_;

  std::mutex lifecycle_mutex_;
  std::thread thread_;
  int wake_fd_ = -1;
  std::atomic<bool> running_{false};
  std::atomic<std::uint16_t> bound_port_{0};
};

}  // namespace rigger::plc
