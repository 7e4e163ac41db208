#include "rigger/crane_protocol/modbus_context.hpp"

#include <arpa/inet.h>

#include <cerrno>

namespace rigger::crane {

void ModbusContextDeleter::operator()(modbus_t* context) const noexcept {
  if (context != nullptr) {
    modbus_close(context);
    modbus_free(context);
  }
}

std::string modbus_error_text(int errnum) { return modbus_strerror(errnum); }

ModbusContextPtr make_tcp_client(const std::string& host, std::uint16_t port,
                                 std::chrono::microseconds response_timeout, int unit_id) {
  if (response_timeout <= std::chrono::microseconds::zero()) {
    throw ModbusError("modbus client " + host + ": response timeout must be positive");
  }
  const std::string service = std::to_string(port);
  // A numeric IPv4 address takes the plain TCP backend: no getaddrinfo(), so no name service that
  // could block a cycle, and no AI_ADDRCONFIG surprises on hosts with only a loopback interface.
  in_addr numeric{};
  const bool ipv4 = inet_pton(AF_INET, host.c_str(), &numeric) == 1;
  ModbusContextPtr context(ipv4 ? modbus_new_tcp(host.c_str(), port)
                                : modbus_new_tcp_pi(host.c_str(), service.c_str()));
  if (!context) {
    throw ModbusError("modbus client " + host + ":" + service + ": " + modbus_error_text(errno));
  }
  const auto seconds = std::chrono::duration_cast<std::chrono::seconds>(response_timeout);
  const auto micros = response_timeout - seconds;
  const auto sec = static_cast<std::uint32_t>(seconds.count());
  const auto usec = static_cast<std::uint32_t>(micros.count());
  if (modbus_set_response_timeout(context.get(), sec, usec) != 0 ||
      modbus_set_byte_timeout(context.get(), sec, usec) != 0 ||
      modbus_set_slave(context.get(), unit_id) != 0) {
    throw ModbusError("modbus client " + host + ":" + service +
                      ": bad timeout or unit id: " + modbus_error_text(errno));
  }
  return context;
}

}  // namespace rigger::crane
