// The world model's side of the cell file: the store built from it keeps every configured entity as the
// shared reader (rigger_cell_config, tested in common/cell_config/test) gives it, and errors keep the
// reader's "<file>: <pointer>: expected ..." form.
#include <string>

#include <gtest/gtest.h>

#include "cell_fixture.hpp"

#include "world_cell_config.hpp"
#include "world_store.hpp"

namespace rigger::world {
namespace {

const Stamp kLoadedAt{std::chrono::seconds(100)};

TEST(CellConfig, TheStoreHoldsTheConfiguredEntities) {
  const CellConfig config = load_cell_config(testing::fixture_cell_path());
  const WorldStore store = WorldStore::from_config(config, kLoadedAt);
  ASSERT_EQ(store.entities().size(), config.entities.size());
  for (const cell::CellEntity& configured : config.entities) {
    const Entity& entity = store.entities().at(configured.id);
    EXPECT_EQ(entity.kind, configured.kind) << configured.id;
    EXPECT_EQ(entity.parent, configured.parent) << configured.id;
    EXPECT_EQ(entity.localized, configured.localized) << configured.id;
    EXPECT_EQ(entity.pose.has_value(), configured.pose_parent_entity.has_value()) << configured.id;
    if (entity.pose) {
      EXPECT_TRUE(entity.pose->pose_parent_entity.isApprox(*configured.pose_parent_entity)) << configured.id;
      EXPECT_EQ(entity.pose->stamp, kLoadedAt);
      EXPECT_FALSE(entity.pose->quality.has_value());
    }
    EXPECT_EQ(entity.attributes, configured.attributes) << configured.id;
    EXPECT_EQ(entity.model.has_value(), configured.model.has_value()) << configured.id;
    EXPECT_EQ(entity.camera.has_value(), configured.camera.has_value()) << configured.id;
    EXPECT_EQ(entity.features.empty(), configured.features.empty()) << configured.id;
  }
  const Entity& load = store.entities().at("load");
  EXPECT_FALSE(load.localized) << "objects wait for perception";
  ASSERT_TRUE(load.features.find_pose("grasp_side").has_value());
  EXPECT_TRUE(store.entities().at("robot").localized) << "calibrated devices are localized by the configuration";
}

TEST(CellConfig, ErrorsNameTheFileAndTheJsonPointer) {
  try {
    parse_cell_config(R"({"cell_version": 1, "entities": [{"id": "world", "kind": "robot"}]})", "cell.json");
    ADD_FAILURE() << "expected an error";
  } catch (const CellConfigError& error) {
    EXPECT_EQ(error.file(), "cell.json");
    EXPECT_EQ(error.pointer(), "/entities/0/kind");
    EXPECT_EQ(std::string(error.what()),
              "cell.json: /entities/0/kind: expected \"object\", \"device\" or \"frame\", got string \"robot\"");
  }
}

}  // namespace
}  // namespace rigger::world
