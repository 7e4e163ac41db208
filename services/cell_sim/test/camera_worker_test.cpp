#include "camera_worker.hpp"

#include <gtest/gtest.h>

#include <condition_variable>
#include <mutex>

#include "cell_sim_config.hpp"

namespace rigger::cell_sim {
namespace {

using namespace std::chrono_literals;

sim::CameraScene cell_scene() {
  return sim::load_camera_scene(default_cell_file());
}

TEST(ResizeCamera, ScalesTheIntrinsicsWithTheImage) {
  const sim::CameraScene full = cell_scene();
  const sim::CameraScene half = resize_camera(full, 640, 360);
  EXPECT_EQ(half.camera.width_px, 640);
  EXPECT_EQ(half.camera.height_px, 360);
  EXPECT_DOUBLE_EQ(half.camera.fx_px, full.camera.fx_px / 2);
  EXPECT_DOUBLE_EQ(half.camera.fy_px, full.camera.fy_px / 2);
  // The principal point keeps its place relative to the image's corner (pixel centres at integers).
  EXPECT_DOUBLE_EQ(half.camera.cx_px + 0.5, (full.camera.cx_px + 0.5) / 2);
  EXPECT_DOUBLE_EQ(half.camera.cy_px + 0.5, (full.camera.cy_px + 0.5) / 2);
}

TEST(ResizeCamera, ZeroKeepsTheConfiguredSize) {
  const sim::CameraScene full = cell_scene();
  EXPECT_EQ(resize_camera(full, 0, 0).camera.width_px, full.camera.width_px);
}

TEST(ResizeCamera, RefusesAnotherAspectRatio) {
  EXPECT_THROW(resize_camera(cell_scene(), 640, 480), std::invalid_argument);
  EXPECT_THROW(resize_camera(cell_scene(), 640, 0), std::invalid_argument);
}

class CameraWorkerTest : public ::testing::Test {
 protected:
  /// Waits until `n` frames arrived.
  bool wait_frames(std::size_t n) {
    std::unique_lock<std::mutex> lock(mutex_);
    return cv_.wait_for(lock, 10s, [&] { return sizes_.size() >= n; });
  }
  CameraWorker::OnFrame recorder() {
    return [this](const cv::Mat& image, WallTime stamp) {
      const std::lock_guard<std::mutex> lock(mutex_);
      sizes_.push_back(image.size());
      stamps_.push_back(stamp);
      means_.push_back(cv::mean(image)[0]);
      cv_.notify_all();
    };
  }
  std::mutex mutex_;
  std::condition_variable cv_;
  std::vector<cv::Size> sizes_;
  std::vector<WallTime> stamps_;
  std::vector<double> means_;
};

TEST_F(CameraWorkerTest, RendersEachSnapshotWithItsStamp) {
  const sim::CameraScene scene = resize_camera(cell_scene(), 320, 180);
  sim::RenderSettings settings;
  settings.noise_stddev = 0.0;
  CameraWorker worker(scene, settings, recorder());
  const WallTime stamp = WallTime(std::chrono::seconds(1'800'000'000));
  std::vector<sim::ObjectPose> poses;
  for (const auto& object : scene.objects) poses.push_back({object.id, object.pose_world_object});
  worker.offer({poses, stamp});
  ASSERT_TRUE(wait_frames(1));
  worker.offer({{}, stamp + 1s});  // nothing in view: the background only
  ASSERT_TRUE(wait_frames(2));
  const std::lock_guard<std::mutex> lock(mutex_);
  EXPECT_EQ(sizes_[0], cv::Size(320, 180));
  EXPECT_EQ(stamps_[0], stamp);
  EXPECT_EQ(stamps_[1], stamp + 1s);
  EXPECT_NE(means_[0], means_[1]);  // the boxes changed the picture
  EXPECT_EQ(worker.frames(), 2u);
}

TEST_F(CameraWorkerTest, SnapshotsOfferedWhileBusyReplaceEachOther) {
  const sim::CameraScene scene = cell_scene();  // full size: slow enough to be busy
  CameraWorker worker(scene, {}, recorder());
  std::vector<sim::ObjectPose> poses;
  for (const auto& object : scene.objects) poses.push_back({object.id, object.pose_world_object});
  constexpr int kOffers = 20;
  for (int i = 0; i < kOffers; ++i) worker.offer({poses, WallTime(std::chrono::seconds(i))});
  // Every offer is either rendered or dropped, and the last one is always rendered.
  ASSERT_TRUE(wait_frames(1));
  std::unique_lock<std::mutex> lock(mutex_);
  ASSERT_TRUE(cv_.wait_for(
      lock, 10s, [&] { return !stamps_.empty() && stamps_.back() == WallTime(std::chrono::seconds(kOffers - 1)); }));
  EXPECT_EQ(worker.frames() + worker.dropped(), static_cast<std::uint64_t>(kOffers));
  EXPECT_GT(worker.dropped(), 0u);
}

}  // namespace
}  // namespace rigger::cell_sim
