#include <unistd.h>

#include <filesystem>
#include <fstream>

#include <gtest/gtest.h>

#include "cell_fixture.hpp"
#include <sqlite3.h>

#include "world_cell_config.hpp"
#include "world_persistence.hpp"
#include "world_queries.hpp"

namespace rigger::world {
namespace {

namespace fs = std::filesystem;
using std::chrono::seconds;

const Stamp kLoadedAt{seconds(1000)};

class WorldPersistenceTest : public ::testing::Test {
 protected:
  void SetUp() override {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    dir_ = fs::temp_directory_path() / ("rigger-wm-" + std::to_string(::getpid()) + "-" + info->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
    path_ = dir_ / "world.db";
  }
  void TearDown() override { fs::remove_all(dir_); }

  static WorldStore fresh_store(Stamp loaded_at = kLoadedAt) {
    return WorldStore::from_config(load_cell_config(testing::fixture_cell_path()),
                                   loaded_at);
  }

  static EntityUpdate pose_update(const std::string& id, Stamp stamp, const Eigen::Vector3d& position) {
    EntityUpdate update;
    update.entity_id = id;
    update.source = "vision_tracker";
    update.stamp = stamp;
    update.pose = PoseValue{position, Eigen::Quaterniond(Eigen::AngleAxisd(0.3, Eigen::Vector3d::UnitZ()))};
    return update;
  }

  // Applies and saves, as the world model's work loop does.
  static void apply_and_save(WorldStore& store, WorldDatabase& db, const EntityUpdate& update) {
    const UpdateResult result = store.apply(update);
    ASSERT_TRUE(result.accepted()) << result.reason;
    const SaveResult saved = db.save(*result.change);
    ASSERT_TRUE(saved.ok) << saved.error;
  }

  // Runs SQL on the database file behind the world model's back.
  static void exec_sql(const fs::path& path, const char* sql) {
    sqlite3* raw = nullptr;
    ASSERT_EQ(sqlite3_open(path.c_str(), &raw), SQLITE_OK);
    EXPECT_EQ(sqlite3_exec(raw, sql, nullptr, nullptr, nullptr), SQLITE_OK) << sql;
    sqlite3_close(raw);
  }

  static void write_file(const fs::path& path, const std::string& bytes) {
    std::ofstream file(path, std::ios::binary | std::ios::trunc);
    file << bytes;
  }

  static void expect_open_error(const fs::path& path, const std::string& part) {
    try {
      WorldDatabase::open(path);
      ADD_FAILURE() << "expected PersistenceError for " << path;
    } catch (const PersistenceError& error) {
      EXPECT_NE(std::string(error.what()).find(path.string()), std::string::npos) << error.what();
      EXPECT_NE(std::string(error.what()).find(part), std::string::npos) << error.what();
    }
  }

  fs::path dir_;
  fs::path path_;
};

TEST_F(WorldPersistenceTest, ANewDatabaseIsEmpty) {
  WorldDatabase db = WorldDatabase::open(path_);
  const PersistedWorld world = db.load();
  EXPECT_TRUE(world.entities.empty());
  EXPECT_EQ(world.revision, 0u);
  EXPECT_EQ(db.change_log_size(), 0u);
  EXPECT_TRUE(fs::exists(path_));
}

TEST_F(WorldPersistenceTest, ARestartKeepsEntitiesAndMarksPosesStale) {
  const Stamp observed = kLoadedAt + seconds(10);
  {
    WorldDatabase db = WorldDatabase::open(path_);
    WorldStore store = fresh_store();
    apply_and_save(store, db, pose_update("load", kLoadedAt + seconds(5), {3.5, 1.7, 1.2}));
    EntityUpdate update = pose_update("load", observed, {3.6, 1.8, 1.25});
    Covariance6d covariance = Covariance6d::Identity() * 1e-4;
    update.covariance = covariance;
    update.quality = 0.9;
    update.attributes_patch = nlohmann::json{{"batch", 7}};
    apply_and_save(store, db, update);
    apply_and_save(store, db, pose_update("target", kLoadedAt + seconds(6), {3.55, 2.25, 0.95}));
    EXPECT_EQ(db.change_log_size(), 3u);
    ASSERT_TRUE(is_localized(store, "load", seconds(5), observed).value.localized);
  }

  // The restarted world model: configuration first, then the persisted state on top.
  WorldDatabase db = WorldDatabase::open(path_);
  const PersistedWorld persisted = db.load();
  EXPECT_EQ(persisted.revision, 3u);
  ASSERT_EQ(persisted.entities.size(), 2u);
  WorldStore store = fresh_store(kLoadedAt + seconds(60));
  const RestoreReport report = store.restore_stale(persisted);
  EXPECT_EQ(report.restored.size(), 2u);
  EXPECT_TRUE(report.ignored.empty());

  const Entity* load = store.find("load");
  ASSERT_NE(load, nullptr);
  EXPECT_TRUE(load->stale);
  EXPECT_FALSE(load->localized) << "a restored pose is never fresh";
  ASSERT_TRUE(load->pose.has_value());
  EXPECT_TRUE(load->pose->pose_parent_entity.translation().isApprox(Eigen::Vector3d(3.6, 1.8, 1.25)));
  EXPECT_TRUE(load->pose->pose_parent_entity.linear().isApprox(
      Eigen::AngleAxisd(0.3, Eigen::Vector3d::UnitZ()).toRotationMatrix(), 1e-12));
  EXPECT_EQ(load->pose->stamp, observed);
  EXPECT_EQ(load->stamp, observed);
  EXPECT_EQ(load->pose->source, "vision_tracker");
  EXPECT_EQ(*load->pose->quality, 0.9);
  EXPECT_EQ(*load->pose->covariance, Covariance6d::Identity() * 1e-4);
  EXPECT_EQ(load->attributes["batch"], 7);
  EXPECT_FALSE(load->features.grasp_frames.empty()) << "features come from the configuration";

  const auto answer = is_localized(store, "load", std::nullopt, observed);
  EXPECT_FALSE(answer.value.localized);
  EXPECT_EQ(answer.value.state, LocalizationState::kStale);
  // Entities never changed keep their configuration state.
  EXPECT_FALSE(store.find("robot")->stale);
  EXPECT_TRUE(store.find("robot")->localized);

  // Revisions continue; an update older than the restored state is still refused.
  EXPECT_EQ(store.revision(), 3u);
  EXPECT_EQ(store.apply(pose_update("load", observed - seconds(1), {0, 0, 0})).status, UpdateStatus::kStampBackwards);
  const UpdateResult next = store.apply(pose_update("load", observed + seconds(1), {3.6, 1.8, 1.25}));
  ASSERT_TRUE(next.accepted());
  EXPECT_EQ(next.change->revision, 4u);
  EXPECT_EQ(next.change->what(), "pose,covariance,quality,localized,stale");
  EXPECT_FALSE(store.find("load")->stale);
  EXPECT_TRUE(store.find("load")->localized);
  ASSERT_TRUE(db.save(*next.change).ok);
  EXPECT_EQ(db.load().revision, 4u);
}

TEST_F(WorldPersistenceTest, ARestoredReparentingIsKept) {
  {
    WorldDatabase db = WorldDatabase::open(path_);
    WorldStore store = fresh_store();
    apply_and_save(store, db, pose_update("gripper", kLoadedAt + seconds(1), {0.5, 0, 0.3}));
    EntityUpdate attach = pose_update("load", kLoadedAt + seconds(2), {0, 0, 0.32});
    attach.parent = "gripper";
    apply_and_save(store, db, attach);
  }
  WorldDatabase db = WorldDatabase::open(path_);
  WorldStore store = fresh_store();
  store.restore_stale(db.load());
  EXPECT_EQ(store.find("load")->parent, "gripper");
  const auto in_robot = pose_of(store, "load", "robot");
  ASSERT_TRUE(in_robot.ok()) << in_robot.message;
  EXPECT_TRUE(in_robot.value.any_stale);
  EXPECT_FALSE(in_robot.value.all_localized);
}

TEST_F(WorldPersistenceTest, EntitiesNoLongerConfiguredAreIgnored) {
  PersistedWorld persisted;
  Entity ghost;
  ghost.id = "crate";
  ghost.parent = "world";
  persisted.entities.push_back(ghost);
  Entity orphan;
  orphan.id = "load";
  orphan.parent = "shelf";
  persisted.entities.push_back(orphan);
  persisted.revision = 9;
  WorldStore store = fresh_store();
  const RestoreReport report = store.restore_stale(persisted);
  EXPECT_TRUE(report.restored.empty());
  EXPECT_EQ(report.ignored, (std::vector<std::string>{"crate", "load"}));
  EXPECT_FALSE(store.find("load")->stale);
  EXPECT_EQ(store.find("load")->parent, "world");
  EXPECT_EQ(store.revision(), 9u) << "revisions continue even when nothing is restored";
}

TEST_F(WorldPersistenceTest, ACorruptedFileIsAClearError) {
  write_file(path_, std::string(4096, 'x') + "this is not a database");
  expect_open_error(path_, "not a database");
}

TEST_F(WorldPersistenceTest, ADamagedDatabaseFailsTheIntegrityCheck) {
  {
    WorldDatabase db = WorldDatabase::open(path_);
    WorldStore store = fresh_store();
    for (int i = 1; i <= 300; ++i) {
      apply_and_save(store, db, pose_update(i % 2 == 0 ? "load" : "target", kLoadedAt + seconds(i), {i * 0.01, 0, 0}));
    }
  }
  // Checkpointed on close: the data lives in the main file. Overwrite pages past the header.
  const auto size = fs::file_size(path_);
  ASSERT_GT(size, 8192u);
  {
    std::fstream file(path_, std::ios::binary | std::ios::in | std::ios::out);
    file.seekp(4096);
    const std::string garbage(static_cast<std::size_t>(size) - 4096, '\xA5');
    file.write(garbage.data(), static_cast<std::streamsize>(garbage.size()));
  }
  try {
    WorldDatabase db = WorldDatabase::open(path_);
    db.load();
    ADD_FAILURE() << "expected PersistenceError";
  } catch (const PersistenceError& error) {
    EXPECT_NE(std::string(error.what()).find(path_.string()), std::string::npos) << error.what();
  }
}

TEST_F(WorldPersistenceTest, AnotherApplicationsDatabaseIsRefused) {
  exec_sql(path_, "CREATE TABLE notes (text TEXT)");
  expect_open_error(path_, "not a rigger world-model database");
}

TEST_F(WorldPersistenceTest, AnotherSchemaVersionIsRefused) {
  { WorldDatabase::open(path_); }
  exec_sql(path_, "PRAGMA user_version = 7");
  expect_open_error(path_, "schema version 7");
}

TEST_F(WorldPersistenceTest, AMalformedRowNamesTheEntity) {
  { WorldDatabase::open(path_); }
  exec_sql(path_, "INSERT INTO entity_state VALUES ('load', 1, '{\"id\": \"load\", \"kind\": \"rock\"}')");
  WorldDatabase db = WorldDatabase::open(path_);
  try {
    db.load();
    ADD_FAILURE() << "expected PersistenceError";
  } catch (const PersistenceError& error) {
    EXPECT_NE(std::string(error.what()).find("entity_state row \"load\" is malformed"), std::string::npos) << error.what();
  }
}

TEST_F(WorldPersistenceTest, AnUnopenablePathIsAClearError) {
  expect_open_error(dir_ / "missing-dir" / "world.db", "unable to open");
}

TEST_F(WorldPersistenceTest, TheChangeLogIsPruned) {
  WorldDatabaseOptions options;
  options.max_change_log_rows = 10;
  WorldDatabase db = WorldDatabase::open(path_, options);
  WorldStore store = fresh_store();
  for (int i = 1; i <= 300; ++i) apply_and_save(store, db, pose_update("load", kLoadedAt + seconds(i), {0, 0, 0}));
  // Pruned once, after 256 saves, down to the newest 10; 44 more since.
  EXPECT_EQ(db.change_log_size(), 54u);
  EXPECT_EQ(db.load().revision, 300u);
}

TEST_F(WorldPersistenceTest, ASaveFailureIsReportedNotThrown) {
  WorldDatabase db = WorldDatabase::open(path_);
  WorldStore store = fresh_store();
  const UpdateResult result = store.apply(pose_update("load", kLoadedAt + seconds(1), {0, 0, 0}));
  ASSERT_TRUE(result.accepted());
  exec_sql(path_, "DROP TABLE change_log");
  const SaveResult saved = db.save(*result.change);
  EXPECT_FALSE(saved.ok);
  EXPECT_NE(saved.error.find(path_.string()), std::string::npos) << saved.error;
}

}  // namespace
}  // namespace rigger::world
