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

}  // namespace
}  // namespace rigger::crane_gateway
