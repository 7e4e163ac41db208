#include "cad_node.hpp"

int main(int argc, char** argv) {
  return rigger::service::run_service(
      argc, argv,
      {"cad",
       "CAD models (STEP, OpenCascade): features, tessellation, frames and skill parameters from picks.",
       {},
       [](rigger::service::ServiceContext& ctx) -> std::unique_ptr<rigger::service::Node> {
         return std::make_unique<rigger::cad_service::CadNode>(ctx, rigger::cad_service::read_settings(ctx.config));
       }});
}
