#include "cell_sim_node.hpp"

int main(int argc, char** argv) {
  rigger::cell_sim::CommandLine overrides;
  return rigger::service::run_service(argc, argv,
                                      {"cell_sim", "The simulated cell: physics, crane PLC emulator, camera.",
                                       [&overrides](CLI::App& app) { overrides.add_to(app); },
                                       [&overrides](rigger::service::ServiceContext& ctx) {
                                         return std::make_unique<rigger::cell_sim::CellSimNode>(ctx, overrides);
                                       }});
}
