#include "crane_gateway_node.hpp"

int main(int argc, char** argv) {
  rigger::crane_gateway::CommandLine overrides;
  return rigger::service::run_service(argc, argv,
                                      {"crane_gateway", "The only bridge to the crane PLC (Modbus TCP).",
                                       [&overrides](CLI::App& app) { overrides.add_to(app); },
                                       [&overrides](rigger::service::ServiceContext& ctx) {
                                         return std::make_unique<rigger::crane_gateway::CraneGatewayNode>(ctx,
                                                                                                          overrides);
                                       }});
}
