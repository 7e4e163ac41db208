// The vision tracker node in-process on a private domain: rendered images in, poses out.
#include <gtest/gtest.h>

#include <chrono>
#include <cstdio>
#include <map>
#include <memory>
#include <vector>

#include "rigger/dds/conversions.hpp"
#include "rigger/dds/service.hpp"
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
        context_{options_, null_logger(), participant_, loop_, announcer_,
                 Config::parse(R"({"cell_file": "deploy/cell/simulated_cell.json"})", "test")},
        scene_(sim::load_camera_scene(testing::deployed_cell_json_path())),
        renderer_(scene_, testing::render_settings(2.0)),
        images_(participant_, kImageTopic, dds::qos::sensor_stream()),
        commands_(participant_, kCommandTopic, dds::qos::commands()),
        poses_(participant_, kPoseTopic, dds::qos::sensor_stream()) {
    node_ = std::make_unique<VisionTrackerNode>(context_);
    loop_.on_data(poses_, [this] {
      poses_.take([this](const rigger_vision_TrackedPose& p, const dds_sample_info_t&) {
        Received r;
        r.stamp = dds::to_domain(p.header.stamp);
        r.frame = dds::to_string(p.header.frame_id);
        r.tracked = p.tracked;
        r.quality = p.quality;
        r.markers_used = p.markers_used;
        r.pose = dds::to_domain(p.pose.pose);
        received_[dds::to_string(p.object_id)].push_back(r);
      });
    });
  }

  void command(rigger_vision_TrackerCommandKind kind) {
    rigger_vision_TrackerCommand cmd{};
    cmd.header.stamp = dds::wire_now();
    cmd.seq = ++seq_;
    cmd.kind = kind;
    cmd.source = dds::wire_string(source_);
    ASSERT_EQ(commands_.write(cmd), DDS_RETCODE_OK);
    const auto before = node_->mode();
    // The command is processed when the mode changes (every test command changes it).
    ASSERT_TRUE(loop_.run_until([&] { return node_->mode() != before; }, 5s));
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

  std::vector<sim::ObjectPose> visible_poses() {
    std::mt19937 rng(3);
    return testing::random_visible_poses(renderer_, scene_, rng);
  }

  cv::Mat render(const std::vector<sim::ObjectPose>& poses) {
    cv::Mat image;
    EXPECT_EQ(renderer_.render(scene_.pose_world_camera, poses, image), sim::RenderStatus::kOk);
    return image;
  }

  struct Received {
    WallTime stamp;
    std::string frame;
    bool tracked = false;
    double quality = 0;
    std::uint32_t markers_used = 0;
    Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  };

  rigger::testing::DomainLease lease_;
  dds::ServiceOptions options_{"vision_tracker-test", 0, "", "info"};
  dds::Participant participant_;
  dds::EventLoop loop_;
  dds::ServiceAnnouncer announcer_;
  dds::ServiceContext context_;
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

TEST_F(VisionTrackerNodeTest, IdleProcessesNothingAndTrackOnceProcessesOneImage) {
  EXPECT_EQ(node_->mode(), TrackerMode::kIdle);
  const cv::Mat image = render(visible_poses());
  const WallTime t0 = std::chrono::system_clock::now();
  command(rigger_vision_TRACK_ONCE);
  send(image, t0);
  ASSERT_TRUE(loop_.run_until([&] { return node_->images_processed() == 1; }, 5s));
  EXPECT_EQ(node_->mode(), TrackerMode::kIdle);
  // Idle again: the next image is taken and ignored; only the image after the next TRACK_ONCE counts.
  send(image, t0 + 33ms);
  ASSERT_TRUE(loop_.run_until([&] { return node_->images_ignored() == 1; }, 5s));
  command(rigger_vision_TRACK_ONCE);
  send(image, t0 + 66ms);
  ASSERT_TRUE(loop_.run_until([&] { return node_->images_processed() == 2; }, 5s));
  const std::size_t objects = scene_.objects.size();
  ASSERT_TRUE(loop_.run_until([&] {
    std::size_t done = 0;
    for (const auto& entry : received_) done += entry.second.size() == 2 ? 1 : 0;
    return done == objects;
  }, 5s));
  for (const auto& [id, list] : received_) {
    ASSERT_EQ(list.size(), 2u) << id;
    EXPECT_EQ(to_unix_ns(list.back().stamp), to_unix_ns(t0 + 66ms)) << id;
  }
  EXPECT_EQ(node_->images_dropped(), 0u);
}

}  // namespace
}  // namespace rigger::vision
