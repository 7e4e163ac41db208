#include "rigger/plc/modbus_register_server.hpp"

#include <gtest/gtest.h>

#include <cerrno>
#include <chrono>

#include "rigger/crane_protocol/modbus_context.hpp"

namespace rigger::plc {
namespace {

using namespace std::chrono_literals;

ModbusServerConfig ephemeral() {
  ModbusServerConfig c;
  c.port = 0;
  return c;
}

crane::ModbusContextPtr connect(std::uint16_t port) {
  auto client = crane::make_tcp_client("127.0.0.1", port, 200ms);
  EXPECT_EQ(modbus_connect(client.get()), 0) << crane::modbus_error_text(errno);
  return client;
}

TEST(ModbusRegisterServer, ServesRegistersOnAnEphemeralPort) {
  ModbusRegisterServer server(ephemeral(), 20, 0, 4);
  server.with_registers([](std::uint16_t* registers, std::size_t count) {
    ASSERT_EQ(count, 20U);
    registers[10] = 0xBEEF;
    registers[19] = 7;
  });
  server.start();
  ASSERT_NE(server.port(), 0);
  auto client = connect(server.port());
  std::uint16_t values[10] = {};
  ASSERT_EQ(modbus_read_registers(client.get(), 10, 10, values), 10);
  EXPECT_EQ(values[0], 0xBEEF);
  EXPECT_EQ(values[9], 7);
  EXPECT_EQ(server.stats().connections_accepted, 1U);
  EXPECT_GE(server.stats().requests_served, 1U);
}

TEST(ModbusRegisterServer, WritesOnlyInsideTheWritableRange) {
  ModbusRegisterServer server(ephemeral(), 20, 2, 4);  // writable: 2..5
  server.start();
  auto client = connect(server.port());
  const std::uint16_t values[4] = {1, 2, 3, 4};
  EXPECT_EQ(modbus_write_registers(client.get(), 2, 4, values), 4);
  EXPECT_EQ(modbus_write_register(client.get(), 5, 9), 1);

  EXPECT_EQ(modbus_write_registers(client.get(), 3, 4, values), -1);  // 3..6
  EXPECT_EQ(errno, EMBXILADD);
  EXPECT_EQ(modbus_write_register(client.get(), 1, 9), -1);
  EXPECT_EQ(errno, EMBXILADD);
  std::uint16_t read_back[2] = {};
  EXPECT_EQ(modbus_write_and_read_registers(client.get(), 10, 1, values, 0, 2, read_back), -1);
  EXPECT_EQ(errno, EMBXILADD);
  EXPECT_EQ(modbus_read_registers(client.get(), 20, 1, read_back), -1);  // beyond the map
  EXPECT_EQ(errno, EMBXILADD);

  std::uint16_t all[20] = {};
  ASSERT_EQ(modbus_read_registers(client.get(), 0, 20, all), 20);
  EXPECT_EQ(all[1], 0);
  EXPECT_EQ(all[2], 1);
  EXPECT_EQ(all[5], 9);
  EXPECT_EQ(all[6], 0);
  EXPECT_EQ(all[10], 0);
  EXPECT_EQ(server.stats().requests_rejected, 3U);
}

TEST(ModbusRegisterServer, StopDropsClientsAndKeepsTheRegisters) {
  ModbusRegisterServer server(ephemeral(), 8, 0, 8);
  server.start();
  const std::uint16_t port = server.port();
  auto client = connect(port);
  ASSERT_EQ(modbus_write_register(client.get(), 3, 42), 1);
  server.stop();
  server.stop();  // idempotent
  EXPECT_FALSE(server.running());
  std::uint16_t value = 0;
  EXPECT_EQ(modbus_read_registers(client.get(), 3, 1, &value), -1);

  // Restart on the very port the old connections used (SO_REUSEADDR).
  ModbusServerConfig same = ephemeral();
  same.port = port;
  ModbusRegisterServer second(same, 8, 0, 8);
  second.start();
  EXPECT_EQ(second.port(), port);
  second.stop();

  server.start();
  auto again = connect(server.port());
  ASSERT_EQ(modbus_read_registers(again.get(), 3, 1, &value), 1);
  EXPECT_EQ(value, 42);
}

TEST(ModbusRegisterServer, PortInUseIsASetupError) {
  ModbusRegisterServer first(ephemeral(), 8, 0, 8);
  first.start();
  ModbusServerConfig same = ephemeral();
  same.port = first.port();
  ModbusRegisterServer second(same, 8, 0, 8);
  EXPECT_THROW(second.start(), crane::ModbusError);
  ModbusServerConfig bad = ephemeral();
  bad.address = "not-an-address";
  ModbusRegisterServer third(bad, 8, 0, 8);
  EXPECT_THROW(third.start(), crane::ModbusError);
  EXPECT_THROW(ModbusRegisterServer(ephemeral(), 8, 4, 8), crane::ModbusError);
}

TEST(ModbusRegisterServer, RefusesClientsBeyondTheLimit) {
  ModbusServerConfig config = ephemeral();
  config.max_clients = 1;
  ModbusRegisterServer server(config, 8, 0, 8);
  server.start();
  auto first = connect(server.port());
  std::uint16_t value = 0;
  ASSERT_EQ(modbus_read_registers(first.get(), 0, 1, &value), 1);
  auto second = crane::make_tcp_client("127.0.0.1", server.port(), 200ms);
  // The kernel completes the handshake; the server closes the connection at once.
  if (modbus_connect(second.get()) == 0) {
    EXPECT_EQ(modbus_read_registers(second.get(), 0, 1, &value), -1);
  }
  EXPECT_EQ(server.stats().connections_refused, 1U);
  EXPECT_EQ(server.stats().clients, 1);
  ASSERT_EQ(modbus_read_registers(first.get(), 0, 1, &value), 1);
}

TEST(ModbusRegisterServer, ClientsMayNameTheHost) {
  ModbusRegisterServer server(ephemeral(), 8, 0, 8);
  server.with_registers([](std::uint16_t* registers, std::size_t) { registers[2] = 77; });
  server.start();
  auto client = crane::make_tcp_client("localhost", server.port(), 200ms);
  ASSERT_EQ(modbus_connect(client.get()), 0) << crane::modbus_error_text(errno);
  std::uint16_t value = 0;
  ASSERT_EQ(modbus_read_registers(client.get(), 2, 1, &value), 1);
  EXPECT_EQ(value, 77);
}

TEST(ModbusRegisterServer, ReconnectsAfterTheClientGoes) {
  ModbusRegisterServer server(ephemeral(), 8, 0, 8);
  server.start();
  for (int i = 0; i < 3; ++i) {
    auto client = connect(server.port());
    ASSERT_EQ(modbus_write_register(client.get(), 0, static_cast<std::uint16_t>(i)), 1);
  }
  EXPECT_EQ(server.stats().connections_accepted, 3U);
}

}  // namespace
}  // namespace rigger::plc
