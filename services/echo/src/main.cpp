#include "echo_node.hpp"

int main(int argc, char** argv) {
  return rigger::service::run_service(
      argc, argv,
      {"echo", "Echoes rigger/echo/request and reports its peers.", {}, [](rigger::service::ServiceContext& ctx) {
         return std::make_unique<rigger::echo::EchoNode>(ctx);
       }});
}
