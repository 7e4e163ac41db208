// The vision tracker node in-process on a private domain: rendered images in, poses out.
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <map>
#include <memory>
#include <vector>

#include <fstream>
#include <iterator>

#include <nlohmann/json.hpp>

#include "rigger/cell_config/cell_file.hpp"
#include "rigger/dds/conversions.hpp"
#include "rigger/protocol/world.hpp"
#include "rigger/world_protocol/cell_protocol.hpp"
#include "rigger/protocol/vision.hpp"
#include "rigger/service/service.hpp"
#include "rigger/testing/domain.hpp"
#include "sim_support.hpp"
#include "vision_tracker_node.hpp"

namespace rigger::vision {
namespace {

using namespace std::chrono_literals;

class VisionTrackerNodeTest : public ::testing::Test {
 protected:
  VisionTrackerNodeTest()
      : participant_(lease_.id()),
        loop_(participant_),
        announcer_(participant_, "vision_tracker-test", "vision_tracker"),
        scene_(sim::load_camera_scene(testing::deployed_cell_json_path())),
        renderer_(scene_, testing::render_settings(2.0)),
        images_(participant_, protocol::vision::kCameraImage),
        commands_(participant_, protocol::vision::kTrackerCommand),
        poses_(participant_, protocol::vision::kTrackerPose) {
    loop_.on_data(poses_, [this] {
      poses_.take([this](const rigger_vision_TrackedPose& p, const dds_sample_info_t&) {
        Received r;
        r.stamp = dds::to_domain(p.header.stamp);
        r.frame = dds::to_string(p.header.frame_id);
        r.tracked = p.tracked;
        r.quality = p.quality;
        r.markers_used = p.markers_used;
        r.pose = dds::to_domain(p.pose.pose);
        r.status = dds::to_string(p.status);
        r.detail = dds::to_string(p.detail);
        received_[dds::to_string(p.object_id)].push_back(r);
      });
    });
  }

  void SetUp() override { start(); }

  /// (Re)starts the node with the deployed cell and `extra_config` keys (",\"key\": value...").
  void start(const std::string& extra_config = "") {
    node_.reset();
    context_.reset(new service::ServiceContext{
        options_, null_logger(), participant_, loop_, announcer_,
        Config::parse(R"({"cell_file": "deploy/cell/simulated_cell.json")" + extra_config + "}", "test")});
    node_ = std::make_unique<VisionTrackerNode>(*context_);
  }

  /// Sends a command and waits until the node has handled it; returns its stamp.
  WallTime command(rigger_vision_TrackerCommandKind kind, const std::string& object_id = "") {
    rigger_vision_TrackerCommand cmd{};
    const WallTime stamp = std::chrono::system_clock::now();
    cmd.header.stamp = dds::to_wire(stamp);
    cmd.seq = ++seq_;
    cmd.object_id = dds::wire_string(object_id);
    cmd.kind = kind;
    cmd.source = dds::wire_string(source_);
    EXPECT_EQ(commands_.write(cmd), DDS_RETCODE_OK);
    const auto handled = [&] { return node_->commands_applied() + node_->commands_dropped(); };
    const auto before = handled();
    EXPECT_TRUE(loop_.run_until([&] { return handled() > before; }, 5s));
    return stamp;
  }

  /// A stamp for the next image: now, and always after the previous image's.
  WallTime next_stamp() {
    last_stamp_ = std::max(std::chrono::system_clock::now(), last_stamp_ + 1ms);
    return last_stamp_;
  }

  void send(const cv::Mat& image, WallTime stamp, const std::string& encoding = "mono8", int extra_bytes = 0) {
    std::vector<std::uint8_t> data(image.data, image.data + image.total());
    data.resize(static_cast<std::size_t>(static_cast<int>(data.size()) + extra_bytes));
    rigger_vision_Image msg{};
    msg.header.stamp = dds::to_wire(stamp);
    msg.header.frame_id = dds::wire_string(camera_frame_);
    msg.width = static_cast<std::uint32_t>(image.cols);
    msg.height = static_cast<std::uint32_t>(image.rows);
    msg.step = static_cast<std::uint32_t>(image.cols);
    msg.encoding = dds::wire_string(encoding);
    dds::wire_sequence(msg.data, data);
    ASSERT_EQ(images_.write(msg), DDS_RETCODE_OK);
  }

  /// The objects with markers (what the tracker reports), all in view; the part's table has none.
  std::vector<sim::ObjectPose> visible_poses() {
    std::mt19937 rng(3);
    std::vector<sim::ObjectPose> poses = testing::random_visible_poses(renderer_, scene_, rng);
    poses.erase(std::remove_if(poses.begin(), poses.end(),
                               [&](const sim::ObjectPose& p) {
                                 return std::none_of(scene_.objects.begin(), scene_.objects.end(),
                                                     [&](const sim::BoxObject& o) {
                                                       return o.id == p.object_id && !o.markers.empty();
                                                     });
                               }),
                poses.end());
    return poses;
  }

  cv::Mat render(const std::vector<sim::ObjectPose>& poses) {
    cv::Mat image;
    EXPECT_EQ(renderer_.render(scene_.pose_world_camera, poses, image), sim::RenderStatus::kOk);
    return image;
  }

  static nlohmann::json deployed_cell() {
    std::ifstream in(testing::deployed_cell_json_path(), std::ios::binary);
    return nlohmann::json::parse(std::string(std::istreambuf_iterator<char>(in), {}));
  }

  /// Publishes `cell` as revision 2 and waits until the node follows it.
  void revise(const nlohmann::json& cell, const std::string& changes_json) {
    world_protocol::CellRevision revision;
    revision.cell_revision = 2;
    revision.previous_revision = 1;
    revision.cell_json = cell.dump(2);
    revision.sha256 = "sha-2";
    revision.changes_json = changes_json;
    rigger_world_CellRevision wire{};
    world_protocol::to_wire(revision, wire);
    dds::Writer<rigger_world_CellRevision> writer(participant_, protocol::world::kCell);
    ASSERT_EQ(writer.write(wire), DDS_RETCODE_OK);
    ASSERT_TRUE(loop_.run_until([&] { return node_->cell_follower().revision() == 2; }, 5s))
        << node_->cell_follower().last_refusal();
  }

  struct Received {
    WallTime stamp;
    std::string frame;
    bool tracked = false;
    double quality = 0;
    std::uint32_t markers_used = 0;
    Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
    std::string status, detail;
  };

  rigger::testing::DomainLease lease_;
  service::ServiceOptions options_{"vision_tracker-test", 0, "", "info"};
  dds::Participant participant_;
  dds::EventLoop loop_;
  service::ServiceAnnouncer announcer_;
  std::unique_ptr<service::ServiceContext> context_;
  sim::CameraScene scene_;
  sim::CameraRenderer renderer_;
  dds::Writer<rigger_vision_Image> images_;
  dds::Writer<rigger_vision_TrackerCommand> commands_;
  dds::Reader<rigger_vision_TrackedPose> poses_;
  std::unique_ptr<VisionTrackerNode> node_;
  std::map<std::string, std::vector<Received>> received_;
  std::uint64_t seq_ = 0;
  std::string source_ = "test";
  std::string camera_frame_ = "camera";
  WallTime last_stamp_{};
};

TEST_F(VisionTrackerNodeTest, PublishesTheRenderedObjectsPosesWithTheImageStamp) {
  command(rigger_vision_TRACK_CONTINUOUS);
  const auto truth = visible_poses();
  const WallTime stamp = std::chrono::system_clock::now();
  send(render(truth), stamp);
  ASSERT_TRUE(loop_.run_until([&] { return received_.size() == truth.size(); }, 5s));
  EXPECT_EQ(node_->images_processed(), 1u);
  for (const sim::ObjectPose& t : truth) {
    ASSERT_EQ(received_[t.object_id].size(), 1u) << t.object_id;
    const Received& r = received_[t.object_id].front();
    EXPECT_TRUE(r.tracked) << t.object_id;
    EXPECT_GT(r.quality, 0.5) << t.object_id;
    EXPECT_GE(r.markers_used, 1u);
    EXPECT_EQ(r.frame, "world");
    EXPECT_EQ(to_unix_ns(r.stamp), to_unix_ns(stamp));
    const double error_m = testing::translation_error_m(r.pose, t.pose_world_object);
    const double error_rad = testing::rotation_error_rad(r.pose, t.pose_world_object);
    std::printf("%s: translation error %.3f mm, rotation error %.3f deg\n", t.object_id.c_str(), error_m * 1e3,
                error_rad * 180.0 / M_PI);
    EXPECT_LT(error_m, 0.002) << t.object_id;
    EXPECT_LT(error_rad, 0.5 * M_PI / 180.0) << t.object_id;
  }
}

TEST_F(VisionTrackerNodeTest, TrackOnceModelIsAnsweredOnceWithACodeWhenThereIsNoPoseToGive) {
  start(R"(, "once_timeout_s": 0.3)");
  dds::Writer<rigger_vision_Image> depth(participant_, protocol::vision::kCameraDepth);
  // A device has no model: answered at once.
  command(rigger_vision_TRACK_ONCE_MODEL, "robot");
  ASSERT_TRUE(loop_.run_until([&] { return received_.count("robot") != 0; }, 5s));
  EXPECT_EQ(received_["robot"].back().status, "NO_MODEL");
  EXPECT_FALSE(received_["robot"].back().tracked);
  // "" (every object) is refused: one object at a time.
  const auto dropped = node_->commands_dropped();
  command(rigger_vision_TRACK_ONCE_MODEL, "");
  EXPECT_EQ(node_->commands_dropped(), dropped + 1);
  // A depth image that is not the camera's: BAD_DEPTH, never a pose.
  const WallTime asked = command(rigger_vision_TRACK_ONCE_MODEL, "load");
  const std::vector<float> floats(4 * 3, 1.0F);
  rigger_vision_Image msg{};
  msg.header.stamp = dds::to_wire(asked + 1ms);
  msg.width = 4;
  msg.height = 3;
  msg.step = 16;
  msg.encoding = dds::wire_string("32FC1");
  std::vector<std::uint8_t> bytes(reinterpret_cast<const std::uint8_t*>(floats.data()),
                                  reinterpret_cast<const std::uint8_t*>(floats.data()) + 48);
  dds::wire_sequence(msg.data, bytes);
  ASSERT_TRUE(depth.wait_for_readers(1, 5s));
  ASSERT_EQ(depth.write(msg), DDS_RETCODE_OK);
  ASSERT_TRUE(loop_.run_until([&] { return received_.count("load") != 0; }, 5s));
  EXPECT_EQ(received_["load"].back().status, "BAD_DEPTH");
  EXPECT_NE(received_["load"].back().detail.find("size"), std::string::npos) << received_["load"].back().detail;
  EXPECT_FALSE(received_["load"].back().tracked);
  EXPECT_DOUBLE_EQ(received_["load"].back().quality, 0.0);
  // No depth image at all: NO_DEPTH after once_timeout_s, and nothing more.
  command(rigger_vision_TRACK_ONCE_MODEL, "target");
  ASSERT_TRUE(loop_.run_until([&] { return received_.count("target") != 0; }, 5s));
  EXPECT_EQ(received_["target"].back().status, "NO_DEPTH");
  loop_.run_until([] { return false; }, 400ms);
  EXPECT_EQ(received_["target"].size(), 1u);
  EXPECT_EQ(received_["load"].size(), 1u) << "one answer per request";
}

TEST_F(VisionTrackerNodeTest, CorruptImagesAreDroppedAndTheNodeKeepsWorking) {
  command(rigger_vision_TRACK_CONTINUOUS);
  const auto truth = visible_poses();
  const cv::Mat image = render(truth);
  const WallTime t0 = std::chrono::system_clock::now();
  send(image, t0, "mono8", -100);  // data shorter than step * height
  ASSERT_TRUE(loop_.run_until([&] { return node_->images_dropped() == 1; }, 5s));
  send(image, t0 + 1ms, "rgb8");  // wrong encoding
  ASSERT_TRUE(loop_.run_until([&] { return node_->images_dropped() == 2; }, 5s));
  EXPECT_TRUE(received_.empty());
  const WallTime t1 = t0 + 33ms;
  send(image, t1);
  ASSERT_TRUE(loop_.run_until([&] { return received_.size() == truth.size(); }, 5s));
  for (const auto& [id, list] : received_) {
    ASSERT_EQ(list.size(), 1u) << id;
    EXPECT_EQ(to_unix_ns(list.front().stamp), to_unix_ns(t1)) << id;
    EXPECT_TRUE(list.front().tracked) << id;
  }
}

TEST_F(VisionTrackerNodeTest, LostObjectIsReportedUntrackedAtOnceWithQualityZero) {
  command(rigger_vision_TRACK_CONTINUOUS);
  const auto truth = visible_poses();
  const WallTime t0 = std::chrono::system_clock::now();
  send(render(truth), t0);
  ASSERT_TRUE(loop_.run_until([&] { return received_["load"].size() == 1; }, 5s));
  ASSERT_TRUE(received_["load"].back().tracked);
  std::vector<sim::ObjectPose> without_load;
  for (const auto& p : truth) {
    if (p.object_id != "load") without_load.push_back(p);
  }
  const WallTime t1 = t0 + 33ms;
  send(render(without_load), t1);
  ASSERT_TRUE(loop_.run_until([&] { return received_["load"].size() == 2; }, 5s));
  const Received& lost = received_["load"].back();
  EXPECT_FALSE(lost.tracked);
  EXPECT_EQ(lost.quality, 0.0);
  EXPECT_EQ(lost.markers_used, 0u);
  EXPECT_EQ(to_unix_ns(lost.stamp), to_unix_ns(t1));
}

TEST_F(VisionTrackerNodeTest, IdleProcessesNothingAndTrackOnceForAllPublishesEachObjectOnce) {
  EXPECT_FALSE(node_->schedule().any_active());
  const cv::Mat image = render(visible_poses());
  send(image, next_stamp());
  ASSERT_TRUE(loop_.run_until([&] { return node_->images_ignored() == 1; }, 5s));
  command(rigger_vision_TRACK_ONCE);
  const WallTime t1 = next_stamp();
  send(image, t1);
  // Every object with markers (the part's table has none).
  const std::size_t objects = static_cast<std::size_t>(std::count_if(
      scene_.objects.begin(), scene_.objects.end(), [](const sim::BoxObject& o) { return !o.markers.empty(); }));
  ASSERT_TRUE(loop_.run_until([&] { return received_.size() == objects; }, 5s));
  EXPECT_EQ(node_->images_processed(), 1u);
  EXPECT_FALSE(node_->schedule().any_active()) << "every object had its pose: idle again";
  // Idle again: the next image is taken and ignored.
  send(image, next_stamp());
  ASSERT_TRUE(loop_.run_until([&] { return node_->images_ignored() == 2; }, 5s));
  for (const auto& [id, list] : received_) {
    ASSERT_EQ(list.size(), 1u) << id;
    EXPECT_TRUE(list.front().tracked) << id;
    EXPECT_GE(list.front().quality, 0.5) << id;
    EXPECT_EQ(to_unix_ns(list.front().stamp), to_unix_ns(t1)) << id;
  }
  EXPECT_EQ(node_->images_dropped(), 0u);
}

TEST_F(VisionTrackerNodeTest, TrackOnceForOneObjectPublishesOnlyItsFreshPose) {
  const cv::Mat image = render(visible_poses());
  const WallTime before_command = next_stamp();
  const WallTime sent = command(rigger_vision_TRACK_ONCE, "load");
  ASSERT_GT(sent, before_command);
  // An image taken before the command is looked at but does not end TRACK_ONCE.
  send(image, before_command);
  ASSERT_TRUE(loop_.run_until([&] { return node_->images_processed() == 1; }, 5s));
  EXPECT_TRUE(received_.empty());
  EXPECT_TRUE(node_->schedule().once_pending("load"));
  const WallTime fresh = next_stamp();
  send(image, fresh);
  ASSERT_TRUE(loop_.run_until([&] { return received_.count("load") == 1; }, 5s));
  EXPECT_EQ(node_->images_processed(), 2u);
  ASSERT_EQ(received_["load"].size(), 1u);
  EXPECT_TRUE(received_["load"].front().tracked);
  EXPECT_GE(received_["load"].front().quality, 0.5);
  EXPECT_EQ(to_unix_ns(received_["load"].front().stamp), to_unix_ns(fresh));
  EXPECT_GT(received_["load"].front().stamp, sent);
  EXPECT_EQ(received_.count("target"), 0u) << "only the commanded object";
  EXPECT_FALSE(node_->schedule().any_active());
}

TEST_F(VisionTrackerNodeTest, TrackOnceReturnsAContinuousObjectToContinuous) {
  const cv::Mat image = render(visible_poses());
  command(rigger_vision_TRACK_CONTINUOUS, "target");
  command(rigger_vision_TRACK_ONCE, "load");
  send(image, next_stamp());
  ASSERT_TRUE(loop_.run_until([&] { return received_["load"].size() == 1 && received_["target"].size() == 1; }, 5s));
  send(image, next_stamp());
  ASSERT_TRUE(loop_.run_until([&] { return received_["target"].size() == 2; }, 5s));
  EXPECT_EQ(node_->images_processed(), 2u);
  EXPECT_EQ(received_["load"].size(), 1u) << "load went back to idle";
  EXPECT_TRUE(node_->schedule().continuous("target"));
  command(rigger_vision_TRACK_STOP, "target");
  send(image, next_stamp());
  ASSERT_TRUE(loop_.run_until([&] { return node_->images_ignored() == 1; }, 5s));
}

TEST_F(VisionTrackerNodeTest, TrackOnceGivesUpAfterItsTimeoutWithTrackedFalse) {
  start(R"(, "once_timeout_s": 1.0)");
  std::vector<sim::ObjectPose> without_load;
  for (const auto& p : visible_poses()) {
    if (p.object_id != "load") without_load.push_back(p);
  }
  const WallTime sent = command(rigger_vision_TRACK_ONCE, "load");
  send(render(without_load), next_stamp());  // looked at (unless the timeout came first): no load in it
  ASSERT_TRUE(loop_.run_until([&] { return received_.count("load") == 1; }, 5s));
  EXPECT_EQ(node_->images_processed() + node_->images_ignored(), 1u);
  ASSERT_EQ(received_["load"].size(), 1u);
  const Received& lost = received_["load"].front();
  EXPECT_FALSE(lost.tracked);
  EXPECT_EQ(lost.quality, 0.0);
  EXPECT_GT(lost.stamp, sent);
  // Why: the images it looked at, none with a pose of the load.
  EXPECT_EQ(lost.status, "NOT_SEEN");
  EXPECT_EQ(lost.detail, node_->images_processed() == 1 ? "1 image in 1.0 s: no pose of it in any" : "0 images in 1.0 s");
  EXPECT_FALSE(node_->schedule().any_active());
  EXPECT_EQ(received_.count("target"), 0u);
}

TEST_F(VisionTrackerNodeTest, CommandsForUnknownObjectsAreDropped) {
  command(rigger_vision_TRACK_CONTINUOUS, "crane");
  EXPECT_EQ(node_->commands_dropped(), 1u);
  EXPECT_EQ(node_->commands_applied(), 0u);
  EXPECT_FALSE(node_->schedule().any_active());
}

TEST_F(VisionTrackerNodeTest, ACellRevisionWithANewMarkedObjectIsTrackedAndKeepsWhatWasAsked) {
  command(rigger_vision_TRACK_CONTINUOUS, "load");
  nlohmann::json cell = deployed_cell();
  nlohmann::json copy;
  for (const nlohmann::json& entity : cell["entities"]) {
    if (entity["id"] == "load") copy = entity;
  }
  copy["id"] = "load2";
  copy["pose"]["position_m"][0] = copy["pose"]["position_m"][0].get<double>() + 1.0;
  for (nlohmann::json& marker : copy["features"]["markers"]["items"]) marker["id"] = marker["id"].get<int>() + 40;
  copy["features"].erase("rope_attachment");  // the crane carries one load
  cell["entities"].push_back(copy);
  revise(cell, R"({"added":["load2"]})");
  EXPECT_TRUE(node_->schedule().continuous("load")) << "what was asked of a kept object stays";
  command(rigger_vision_TRACK_CONTINUOUS, "load2");
  EXPECT_EQ(node_->commands_dropped(), 0u) << "the new object is known";
  EXPECT_TRUE(node_->schedule().continuous("load2"));
}

// A revision puts the calibration board on the robot's tool; asked for once, its pose comes in the camera's
// optical frame (the board is there to find where the camera is, so not through the cell file's camera pose).
TEST_F(VisionTrackerNodeTest, TheCalibrationBoardIsReportedInTheCameraFrame) {
  nlohmann::json cell = deployed_cell();
  std::ifstream board(std::string(RIGGER_SOURCE_DIR) + "/test/data/calibration_board.json");
  for (nlohmann::json& entity : cell["entities"]) {
    if (entity["id"] == "robot") entity["calibration_board"] = nlohmann::json::parse(board);
  }
  revise(cell, R"({"changed":[{"id":"robot","keys":["calibration_board"]}]})");
  const sim::CameraScene scene = sim::camera_scene_from(cell::cell_file_from_json(cell, "cell with a board"));
  ASSERT_EQ(scene.boards.size(), 1u);
  sim::CameraRenderer renderer(scene, testing::render_settings(2.0));
  // 1.2 m in front of the camera, facing it, tilted.
  const Eigen::Isometry3d pose_camera_board =
      Eigen::Translation3d(0.05, -0.03, 1.2) * Eigen::AngleAxisd(M_PI, Eigen::Vector3d::UnitX()) *
      Eigen::AngleAxisd(0.35, Eigen::Vector3d::UnitY()) * Eigen::AngleAxisd(0.5, Eigen::Vector3d::UnitZ());
  cv::Mat image;
  ASSERT_EQ(renderer.render(scene.pose_world_camera,
                            {{"robot/calibration_board", scene.pose_world_camera * pose_camera_board}}, image),
            sim::RenderStatus::kOk);
  command(rigger_vision_TRACK_ONCE, "robot/calibration_board");
  send(image, next_stamp());
  ASSERT_TRUE(loop_.run_until([&] { return received_.count("robot/calibration_board") == 1; }, 5s));
  const Received& r = received_["robot/calibration_board"].front();
  EXPECT_TRUE(r.tracked);
  EXPECT_EQ(r.frame, "camera");
  EXPECT_EQ(r.markers_used, 9u);
  const double error_m = testing::translation_error_m(r.pose, pose_camera_board);
  const double error_rad = testing::rotation_error_rad(r.pose, pose_camera_board);
  std::printf("board: translation error %.3f mm, rotation error %.3f deg\n", error_m * 1e3, error_rad * 180.0 / M_PI);
  EXPECT_LT(error_m, 0.002);
  EXPECT_LT(error_rad, 0.3 * M_PI / 180.0);
}

}  // namespace
}  // namespace rigger::vision
