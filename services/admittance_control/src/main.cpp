#include "admittance_node.hpp"

int main(int argc, char** argv) {
  return rigger::dds::run_service(argc, argv, {"admittance_control", "Robot and crane admittance control loops.", {},
      [](rigger::dds::ServiceContext& ctx) { return std::make_unique<rigger::control::AdmittanceNode>(ctx); }});
}
