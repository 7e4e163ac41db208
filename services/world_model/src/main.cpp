#include "world_model_node.hpp"

int main(int argc, char** argv) {
  std::string cell_override, database_override;
  return rigger::service::run_service(
      argc, argv,
      {"world_model", "The authoritative store of the cell's entities: queries, validated updates, persistence.",
       [&](CLI::App& app) {
         app.add_option("--cell", cell_override, "cell configuration file (overrides the config's cell_config)");
         app.add_option("--db", database_override, "SQLite state file (overrides the config's database)");
       },
       [&](rigger::service::ServiceContext& ctx) -> std::unique_ptr<rigger::service::Node> {
         auto settings = rigger::world::read_settings(ctx.config);
         if (!cell_override.empty()) settings.cell_config = cell_override;
         if (!database_override.empty()) settings.database = database_override;
         return std::make_unique<rigger::world::WorldModelNode>(ctx, settings);
       }});
}
