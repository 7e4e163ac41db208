#include "admittance_node.hpp"

int main(int argc, char** argv) {
  return rigger::service::run_service(
      argc, argv,
      {"admittance_control", "Robot and crane admittance control loops.", {}, [](rigger::service::ServiceContext& ctx) {
         return std::make_unique<rigger::control::AdmittanceNode>(ctx);
       }});
}
