// The gateway configurations the repository ships load as the gateway reads them at start: the simulated
// cell's, and the real-PLC template of the three-host example (tools/rigger_compose/examples), whose
// cell_file is relative to its own folder.
#include <gtest/gtest.h>

#include "crane_gateway_node.hpp"

namespace rigger::crane_gateway {
namespace {

CraneGatewayConfig load(const std::string& relative) {
  const Config c = Config::load(std::string(RIGGER_SOURCE_DIR) + "/" + relative);
  CraneGatewayConfig out = read_gateway_config(c);
  c.finish();
  return out;
}

TEST(ShippedGatewayConfig, TheSimulatedCellsConfigurationLoads) {
  const CraneGatewayConfig c = load("deploy/config/crane_gateway.json");
  EXPECT_EQ(c.plc_host, "127.0.0.1");
  EXPECT_EQ(c.plc_port, 1502);
}

TEST(ShippedGatewayConfig, TheThreeHostExamplesRealPlcTemplateLoads) {
  const CraneGatewayConfig c = load("tools/rigger_compose/examples/crane_gateway.real.json");
  EXPECT_EQ(c.plc_host, "192.0.2.10");  // a documentation address: the integrator puts the PLC's here
  EXPECT_EQ(c.plc_port, 502);
  EXPECT_GT(c.logic.plausibility.limits.max_speed_mps.maxCoeff(), 0.0);  // the cell file's limits were read
}

/// The error of reading `keys` (JSON members after the cell file's) as the node does, or "".
std::string error_of(const std::string& keys) {
  const std::string cell = std::string(RIGGER_SOURCE_DIR) + "/deploy/cell/simulated_cell.json";
  try {
    const Config c = Config::parse(R"({"cell_file": ")" + cell + "\", " + keys + "}", "gw.json");
    read_gateway_config(c);
    c.finish();
  } catch (const ConfigError& e) {
    return e.what();
  }
  return "";
}

TEST(GatewaySettings, ReadsNestedKeys) {
  const std::string cell = std::string(RIGGER_SOURCE_DIR) + "/deploy/cell/simulated_cell.json";
  const Config c = Config::parse(R"({"cell_file": ")" + cell + R"(", "plc": {"port": 15020, "response_timeout_ms": 80},
      "cycle_rate_hz": 100, "reconnect_backoff_ms": {"min": 5, "max": 50}, "plausibility": {"load_factor": 3}})",
                                 "gw.json");
  const CraneGatewayConfig g = read_gateway_config(c);
  EXPECT_EQ(g.plc_host, "127.0.0.1");
  EXPECT_EQ(g.plc_port, 15020);
  EXPECT_EQ(g.response_timeout, std::chrono::milliseconds(80));
  EXPECT_EQ(g.cycle_period, std::chrono::milliseconds(10));
  EXPECT_EQ(g.reconnect_backoff_min, std::chrono::milliseconds(5));
  EXPECT_EQ(g.reconnect_backoff_max, std::chrono::milliseconds(50));
  EXPECT_DOUBLE_EQ(g.logic.plausibility.load_factor, 3.0);
  EXPECT_DOUBLE_EQ(g.logic.plausibility.speed_factor, 1.25);
  EXPECT_EQ(g.logic.reset_pulse_cycles, 3);
}

TEST(GatewaySettings, OutOfRangeAndUnknownKeysNameTheKeyAndTheFile) {
  EXPECT_EQ(error_of(R"("crane_id": "crane")"), "");
  const std::string port = error_of(R"("plc": {"port": 0})");
  EXPECT_NE(port.find("gw.json"), std::string::npos) << port;
  EXPECT_NE(port.find("/plc/port"), std::string::npos) << port;
  const std::string rate = error_of(R"("cycle_rate_hz": 1000)");
  EXPECT_NE(rate.find("/cycle_rate_hz"), std::string::npos) << rate;
  const std::string unknown = error_of(R"("plc": {"hots": "10.0.0.1"})");
  EXPECT_NE(unknown.find("gw.json"), std::string::npos) << unknown;
  EXPECT_NE(unknown.find("/plc/hots"), std::string::npos) << unknown;
}

}  // namespace
}  // namespace rigger::crane_gateway
