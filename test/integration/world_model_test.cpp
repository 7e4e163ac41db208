// The world_model process: restart with the same database keeps the entities and marks
// poses stale; rejected updates leave the state unchanged and say why; a late-joining reader sees
// every entity at once (transient-local); the change stream says who changed what.
#include <signal.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <optional>
#include <tuple>

#include <gtest/gtest.h>

#include "rigger/dds/conversions.hpp"
#include "rigger/dds/pubsub.hpp"
#include "rigger/protocol/vision.hpp"
#include "rigger/protocol/world.hpp"
#include "rigger/testing/cell.hpp"
#include "rigger/world_client/world_client.hpp"

namespace rigger::testing {
namespace {

using namespace std::chrono_literals;
using world_client::Reply;
using world_client::WorldClient;

class WorldModelTest : public MultiProcessTest {
 protected:
  std::string db_path() const { return cell_.log_dir() + "/world.sqlite"; }

  void start_world(const std::string& id) {
    cell_.start(id, "world_model", {"--id", id, "--db", db_path()});
    ASSERT_TRUE(cell_.wait_ready({id}, 10s)) << cell_.logs();
    if (!client_) client_ = std::make_unique<WorldClient>(cell_.participant(), cell_.loop(), null_logger(), "test-client");
    ASSERT_TRUE(cell_.wait_until([&] { return client_->connected(); }, 5s));
  }

  // Runs one request to its answer.
  template <typename Send>
  Reply call(Send send) {
    std::optional<Reply> got;
    send([&](const Reply& r) { got = r; });
    EXPECT_TRUE(cell_.wait_until([&] { return got.has_value(); }, 5s));
    return got.value_or(Reply{});
  }

  Reply update_load(const Eigen::Isometry3d& pose, WallTime stamp, const std::string& parent = "world") {
    return call([&](WorldClient::Callback cb) { client_->update_pose("load", parent, pose, stamp, 0.9, true, 3s, cb); });
  }
  Reply entity(const std::string& id) {
    return call([&](WorldClient::Callback cb) { client_->entity(id, 3s, cb); });
  }
  Reply localized(const std::string& id, double max_age_s = 0) {
    return call([&](WorldClient::Callback cb) { client_->is_localized(id, max_age_s, 3s, cb); });
  }

  // Asks again (each question a full round trip, no sleep) until `answered()` or 5 s: for effects of
  // samples the test cannot observe directly (the tracker's stream has no reply).
  bool ask_until(const std::function<bool()>& answered) {
    const auto deadline = std::chrono::steady_clock::now() + 5s;
    while (std::chrono::steady_clock::now() < deadline) {
      if (answered()) return true;
    }
    return false;
  }

  static Eigen::Isometry3d load_pose() {
    Eigen::Isometry3d p = Eigen::Isometry3d::Identity();
    p.translation() = Eigen::Vector3d(3.40, 1.80, 1.25);
    p.linear() = Eigen::AngleAxisd(0.2, Eigen::Vector3d::UnitZ()).toRotationMatrix();
    return p;
  }

  /// Raw updates from `source`, written without a WorldClient, and the results the world model
  /// writes for them (code, revision), in order. Construct after start_world.
  struct RawUpdates {
    RawUpdates(WorldModelTest& test, const std::string& source_id)
        : source(source_id),
          writer(test.cell_.participant(), protocol::world::kUpdate),
          results(test.cell_.participant(), protocol::world::kUpdateResult) {
      EXPECT_TRUE(writer.wait_for_readers(1, 5s));
      EXPECT_TRUE(test.cell_.wait_until([&] { return results.matched_writers() > 0; }, 5s));
      test.cell_.loop().on_data(results, [this] {
        results.take([&](const rigger_world_UpdateResult& r, const dds_sample_info_t&) {
          if (dds::to_string(r.source) == source) answers.emplace_back(r.seq, dds::to_string(r.code), r.revision);
        });
      });
      sample.source = dds::wire_string(source);
      sample.entity_id = dds::wire_string(entity);
      sample.parent_frame = dds::wire_string(world);
      sample.attributes_json = dds::wire_string(empty);
    }
    std::string source;
    const std::string entity = "load", world = "world", empty;
    dds::Writer<rigger_world_EntityUpdate> writer;
    dds::Reader<rigger_world_UpdateResult> results;
    rigger_world_EntityUpdate sample{};  ///< entity "load" in "world"; the test sets the rest
    std::vector<std::tuple<std::uint64_t, std::string, std::uint64_t>> answers;  ///< seq, code, revision
  };

  std::unique_ptr<WorldClient> client_;
};

TEST_F(WorldModelTest, RestartKeepsEntitiesAndMarksPosesStale) {
  start_world("wm-a");
  const Reply accepted = update_load(load_pose(), std::chrono::system_clock::now());
  ASSERT_TRUE(accepted.ok) << accepted.code << ": " << accepted.message;
  EXPECT_EQ(accepted.code, "ACCEPTED");
  const Reply before = localized("load", 5.0);
  EXPECT_TRUE(before.localized) << before.code;

  ASSERT_TRUE(cell_.stop("wm-a", SIGINT, 10s).has_value());
  start_world("wm-b");

  const Reply after = localized("load", 0);
  ASSERT_TRUE(after.ok) << after.code << ": " << after.message;
  EXPECT_FALSE(after.localized);
  EXPECT_EQ(after.code, "STALE");
  const Reply e = entity("load");
  ASSERT_TRUE(e.ok);
  EXPECT_EQ(e.result["stale"], true);
  EXPECT_EQ(e.result["localized"], false);
  EXPECT_TRUE(e.pose.isApprox(load_pose(), 1e-9)) << e.pose.matrix();
  // A pose through the restored one is not trusted either.
  const Reply in_robot = call([&](WorldClient::Callback cb) { client_->pose("load", "robot", 3s, cb); });
  ASSERT_TRUE(in_robot.ok);
  EXPECT_FALSE(in_robot.localized);
  EXPECT_EQ(in_robot.result["any_stale"], true);
  // A fresh observation makes it localized again.
  ASSERT_TRUE(update_load(load_pose(), std::chrono::system_clock::now()).ok);
  EXPECT_TRUE(localized("load", 5.0).localized);
}

TEST_F(WorldModelTest, RejectedUpdatesSayWhyAndChangeNothing) {
  start_world("wm-a");
  const WallTime t0 = std::chrono::system_clock::now();
  ASSERT_TRUE(update_load(load_pose(), t0).ok);
  const Reply baseline = entity("load");
  ASSERT_TRUE(baseline.ok);

  Eigen::Isometry3d nan_pose = load_pose();
  nan_pose.translation().x() = std::nan("");
  EXPECT_EQ(update_load(nan_pose, t0 + 1s).code, "NOT_FINITE");
  EXPECT_EQ(update_load(load_pose(), t0 - 1s).code, "STAMP_BACKWARDS");
  EXPECT_EQ(update_load(load_pose(), t0 + 1s, "nowhere").code, "UNKNOWN_PARENT");
  const Reply unknown = call([&](WorldClient::Callback cb) {
    client_->update_pose("crate", "world", load_pose(), t0 + 1s, 1.0, true, 3s, cb);
  });
  EXPECT_EQ(unknown.code, "UNKNOWN_ENTITY");
  EXPECT_FALSE(unknown.message.empty());

  // A non-unit quaternion cannot come out of an Isometry3d: send the raw sample.
  RawUpdates raw(*this, "raw");
  rigger_world_EntityUpdate& u = raw.sample;
  u.parent_frame = dds::wire_string(raw.empty);
  u.has_pose = true;
  u.pose.pose.orientation = {0.0, 0.0, 0.5, 0.5};
  u.stamp = dds::to_wire(t0 + 2s);
  u.seq = 1;
  ASSERT_EQ(raw.writer.write(u), DDS_RETCODE_OK);
  u.pose.pose.orientation = {0.0, 0.0, 0.0, 1.0};
  u.stamp.nanosec = 2000000000u;  // not a time
  u.seq = 2;
  ASSERT_EQ(raw.writer.write(u), DDS_RETCODE_OK);
  u.entity_id = nullptr;  // a null string on the wire
  u.seq = 3;
  ASSERT_EQ(raw.writer.write(u), DDS_RETCODE_OK);
  ASSERT_TRUE(cell_.wait_until([&] { return raw.answers.size() == 3; }, 5s));
  std::map<std::uint64_t, std::string> codes;
  for (const auto& [seq, code, revision] : raw.answers) codes[seq] = code;
  EXPECT_EQ(codes[1], "NON_UNIT_QUATERNION");
  EXPECT_EQ(codes[2], "BAD_STAMP");
  EXPECT_EQ(codes[3], "BAD_ID");

  const Reply after = entity("load");
  ASSERT_TRUE(after.ok);
  EXPECT_EQ(after.result, baseline.result);  // nothing changed, not even the stamp
  EXPECT_TRUE(cell_.process("wm-a").running());
}

TEST_F(WorldModelTest, AnUpdateSentAgainIsAnsweredWithItsResultAndAppliedOnce) {
  // A client that hears no result sends its update again with the same seq (the result may have been
  // written before the world model discovered it): the repeat gets the first result, nothing changes.
  start_world("wm-a");
  RawUpdates again(*this, "again");
  rigger_world_EntityUpdate& u = again.sample;
  u.has_pose = true;
  u.pose.pose.position = {3.5, 2.0, 1.2};
  u.pose.pose.orientation = {0.0, 0.0, 0.0, 1.0};
  u.stamp = dds::to_wire(std::chrono::system_clock::now());
  u.seq = 1;
  ASSERT_EQ(again.writer.write(u), DDS_RETCODE_OK);
  ASSERT_TRUE(cell_.wait_until([&] { return again.answers.size() == 1; }, 5s));
  const Reply applied = entity("load");
  ASSERT_TRUE(applied.ok);
  u.pose.pose.position = {3.0, 2.0, 1.2};  // not read: the update is known by its source and seq
  ASSERT_EQ(again.writer.write(u), DDS_RETCODE_OK);
  ASSERT_TRUE(cell_.wait_until([&] { return again.answers.size() == 2; }, 5s));
  EXPECT_EQ(std::get<1>(again.answers[0]), "ACCEPTED");
  EXPECT_EQ(again.answers[1], again.answers[0]);
  const Reply after = entity("load");
  ASSERT_TRUE(after.ok);
  EXPECT_EQ(after.result, applied.result);
}

TEST_F(WorldModelTest, LateJoinerSeesEveryEntityAtOnceAndTheChangeStreamSaysWhoChangedWhat) {
  start_world("wm-a");
  dds::Reader<rigger_world_EntityChange> changes(cell_.participant(), protocol::world::kChange);
  ASSERT_TRUE(cell_.wait_until([&] { return changes.matched_writers() > 0; }, 5s));
  ASSERT_TRUE(update_load(load_pose(), std::chrono::system_clock::now()).ok);
  std::vector<std::string> change_lines;
  cell_.loop().on_data(changes, [&] {
    changes.take([&](const rigger_world_EntityChange& c, const dds_sample_info_t&) {
      change_lines.push_back(dds::to_string(c.entity_id) + " by " + dds::to_string(c.source) + ": " +
                             dds::to_string(c.what));
    });
  });
  ASSERT_TRUE(cell_.wait_until([&] { return !change_lines.empty(); }, 5s));
  EXPECT_EQ(change_lines[0].rfind("load by test-client: ", 0), 0u) << change_lines[0];
  EXPECT_NE(change_lines[0].find("pose"), std::string::npos);

  // Joins after all of that: must get the whole world from the durable history.
  const Reply list = call([&](WorldClient::Callback cb) { client_->list(3s, cb); });
  ASSERT_TRUE(list.ok);
  dds::Reader<rigger_world_EntityState> late(cell_.participant(), protocol::world::kEntity);
  std::map<std::string, rigger_world_EntityState> seen;
  std::map<std::string, std::string> parents;
  cell_.loop().on_data(late, [&] {
    late.take([&](const rigger_world_EntityState& s, const dds_sample_info_t&) {
      seen[dds::to_string(s.entity_id)] = s;
      parents[dds::to_string(s.entity_id)] = dds::to_string(s.parent_frame);
    });
  });
  ASSERT_TRUE(cell_.wait_until([&] { return seen.size() == list.result.size(); }, 5s));
  for (const auto& id : list.result) EXPECT_EQ(seen.count(id.get<std::string>()), 1u) << id;
  ASSERT_EQ(seen.count("load"), 1u);
  EXPECT_TRUE(seen["load"].has_pose);
  EXPECT_TRUE(seen["load"].localized);
  EXPECT_GT(seen["load"].revision, 0u);
  EXPECT_NEAR(seen["load"].pose.pose.position.x, 3.40, 1e-12);
  EXPECT_EQ(parents["load"], "world");
  EXPECT_EQ(parents["world"], "");
}

TEST_F(WorldModelTest, TrackerPosesLocalizeAndALostObjectIsNoLongerLocalized) {
  start_world("wm-a");
  dds::Writer<rigger_vision_TrackedPose> tracker(cell_.participant(), protocol::vision::kTrackerPose);
  ASSERT_TRUE(tracker.wait_for_readers(1, 5s));
  const std::string object = "load", frame = "world";
  rigger_vision_TrackedPose p{};
  p.object_id = dds::wire_string(object);
  p.header.frame_id = dds::wire_string(frame);
  p.header.stamp = dds::to_wire(std::chrono::system_clock::now());
  p.pose.pose = dds::to_wire(load_pose());
  p.quality = 0.8;
  p.tracked = true;
  // Best effort, as a real tracker stream: the first samples may go out before the world model's
  // reader has matched this writer, so each question follows a fresh sample (as the camera rate would).
  auto publish = [&] {
    p.header.stamp = dds::to_wire(std::chrono::system_clock::now());
    return tracker.write(p) == DDS_RETCODE_OK;
  };
  ASSERT_TRUE(ask_until([&] { return publish() && localized("load", 5.0).localized; }));
  const Reply e = entity("load");
  EXPECT_EQ(e.result["source"], "vision_tracker");
  EXPECT_TRUE(e.pose.isApprox(load_pose(), 1e-9));

  p.tracked = false;
  p.quality = 0.0;
  ASSERT_TRUE(ask_until([&] { return publish() && localized("load", 5.0).code == "NOT_LOCALIZED"; }));
  EXPECT_TRUE(entity("load").pose.isApprox(load_pose(), 1e-9));  // the last pose is kept
}

// The world model derives the cell's CAD features (grasp frames, screw holes, insertion) from the STEP
// models at start-up and answers them as numbers, the same the cell file used to carry by hand.
TEST_F(WorldModelTest, AnswersTheCadFeaturesDerivedFromTheStepModels) {
  start_world("wm-a");
  const Reply target = call([&](WorldClient::Callback cb) { client_->features("target", 3s, cb); });
  ASSERT_TRUE(target.ok) << target.code << ": " << target.message;
  const auto& holes = target.result.at("screw_holes");
  ASSERT_EQ(holes.size(), 4u);
  EXPECT_EQ(holes[0]["id"], "h1");
  EXPECT_EQ(holes[0]["screw_type"], "M12x40");
  const auto h1 = holes[0]["pose"]["position_m"].get<std::vector<double>>();
  EXPECT_NEAR(h1.at(0), -0.15, 1e-6);
  EXPECT_NEAR(h1.at(1), -0.10, 1e-6);
  EXPECT_NEAR(h1.at(2), 0.0, 1e-6);
  const Reply load = call([&](WorldClient::Callback cb) { client_->features("load", 3s, cb); });
  ASSERT_TRUE(load.ok) << load.code << ": " << load.message;
  const auto grasp = load.result.at("grasp_frames").at(0);
  EXPECT_EQ(grasp["id"], "grasp_side");
  EXPECT_NEAR(grasp["pose"]["position_m"][0].get<double>(), -0.20, 1e-6);
  EXPECT_NEAR(grasp["pose"]["rpy_deg"][1].get<double>(), 90.0, 1e-4);
  EXPECT_NEAR(load.result.at("insertion").at("pose_in_target").at("position_m")[2].get<double>(), 0.10, 1e-6);
}

// A cell file whose reference no longer matches its STEP model (here: a signature 1 mm off, as after an
// edit of the model) stops the world model at start-up, saying which object, feature and key.
TEST_F(WorldModelTest, AStaleCadReferenceStopsTheStartWithAClearError) {
  namespace fs = std::filesystem;
  const fs::path dir = fs::path(cell_.log_dir()) / "stale_cell";
  fs::create_directories(dir / "models");
  const fs::path shipped = fs::path(RIGGER_SOURCE_DIR) / "deploy/cell";
  for (const char* name : {"load.step", "target.step", "part.step", "part_fixture.step"})
    fs::copy_file(shipped / "models" / name, dir / "models" / name);
  nlohmann::json cell;
  {
    std::ifstream in(shipped / "simulated_cell.json");
    cell = nlohmann::json::parse(in);
  }
  bool edited = false;
  for (auto& entity : cell["entities"]) {
    if (entity["id"] != "target") continue;
    entity["features"]["screw_holes"][0]["cad"]["hole"]["signature"]["centroid_m"][0] = -0.151;
    edited = true;
  }
  ASSERT_TRUE(edited);
  std::ofstream(dir / "cell.json") << cell.dump(2);

  expect_clean_exit_ = false;  // it must not start
  cell_.start("wm-stale", "world_model", {"--id", "wm-stale", "--cell", (dir / "cell.json").string()});
  const auto status = cell_.process("wm-stale").wait(30s);
  ASSERT_TRUE(status.has_value()) << "the world model started on a stale reference\n" << cell_.logs();
  EXPECT_FALSE(status->ok()) << status->describe();
  const std::string log = cell_.process("wm-stale").log();
  EXPECT_NE(log.find("CAD_STALE_REFERENCE"), std::string::npos) << log;
  EXPECT_NE(log.find("/features/screw_holes/0/cad/hole"), std::string::npos) << log;
  EXPECT_NE(log.find("feature \"h1\" of \"target\""), std::string::npos) << log;
}

}  // namespace
}  // namespace rigger::testing
