#pragma once
// RAII ownership of libmodbus contexts, shared by the crane gateway (client) and the PLC
// emulator (server).

#include <modbus/modbus.h>

#include <chrono>
#include <cstdint>
#include <memory>
#include <stdexcept>
#include <string>

namespace rigger::crane {

/// Closes (if connected) and frees a libmodbus context.
struct ModbusContextDeleter {
  void operator()(modbus_t* context) const noexcept;
};

/// Owner of a libmodbus context. Not thread-safe: one thread uses a context at a time.
using ModbusContextPtr = std::unique_ptr<modbus_t, ModbusContextDeleter>;

/// A libmodbus call failed at setup (bad address, cannot listen, …).
class ModbusError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// libmodbus's text for `errnum` (an errno value or a libmodbus EMB* code).
std::string modbus_error_text(int errnum);

/// A TCP client context for `host` (name or address, IPv4 or IPv6) and `port`, not yet
/// connected. A host name is resolved at every connect (getaddrinfo, which may block on a slow
/// name service); give a numeric address where the connect time must stay bounded. `response_timeout` bounds connect() and each response; the byte timeout is set to
/// the same value. Throws ModbusError on bad arguments.
ModbusContextPtr make_tcp_client(const std::string& host, std::uint16_t port,
                                 std::chrono::microseconds response_timeout, int unit_id = 1);

}  // namespace rigger::crane
