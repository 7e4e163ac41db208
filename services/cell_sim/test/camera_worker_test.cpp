#include "camera_worker.hpp"

#include <gtest/gtest.h>

#include <condition_variable>
#include <mutex>

#include "camera_renderers.hpp"
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

TEST(ResolveRenderer, AutoIsTheRasteriserForBoxesThroughAPinholeAndMujocoForAnythingElse) {
  sim::CellGeometry geometry = sim::load_cell_geometry(default_cell_file());  // the demo cell: boxes
  sim::CameraModel camera = cell_scene().camera;                                // no distortion
  ASSERT_FALSE(geometry.objects.empty());
  EXPECT_EQ(resolve_renderer(CameraRendererKind::kAuto, geometry, camera), CameraRendererKind::kRaster);
  EXPECT_EQ(resolve_renderer(CameraRendererKind::kMujoco, geometry, camera), CameraRendererKind::kMujoco);
  camera.distortion = {-0.1, 0.0, 0.0, 0.0, 0.0};  // the rasteriser refuses a distorting lens
  EXPECT_EQ(resolve_renderer(CameraRendererKind::kAuto, geometry, camera), CameraRendererKind::kMujoco);
  camera.distortion = {0.0, 0.0, 0.0, 0.0};
  geometry.objects.back().box_size_m.reset();  // given by its STEP solids: the rasteriser cannot draw it
  EXPECT_EQ(resolve_renderer(CameraRendererKind::kAuto, geometry, camera), CameraRendererKind::kMujoco);
  EXPECT_EQ(resolve_renderer(CameraRendererKind::kRaster, geometry, camera), CameraRendererKind::kRaster);
}

class CameraWorkerTest : public ::testing::Test {
 protected:
  /// Waits until `n` frames arrived.
  bool wait_frames(std::size_t n) {
    std::unique_lock<std::mutex> lock(mutex_);
    return cv_.wait_for(lock, 10s, [&] { return sizes_.size() >= n; });
  }
  CameraWorker::OnFrame recorder() {
    return [this](const CameraImages& images, WallTime stamp) {
      const std::lock_guard<std::mutex> lock(mutex_);
      sizes_.push_back(images.image_mono8.size());
      stamps_.push_back(stamp);
      means_.push_back(cv::mean(images.image_mono8)[0]);
      depths_.push_back(images.depth_m.clone());
      cv_.notify_all();
    };
  }
  std::mutex mutex_;
  std::condition_variable cv_;
  std::vector<cv::Size> sizes_;
  std::vector<WallTime> stamps_;
  std::vector<double> means_;
  std::vector<cv::Mat> depths_;
};

RendererFactory raster(const sim::CameraScene& scene, sim::RenderSettings settings = {}) {
  return [scene, settings] { return make_raster_renderer(scene, settings); };
}

TEST_F(CameraWorkerTest, RendersEachSnapshotWithItsStamp) {
  const sim::CameraScene scene = resize_camera(cell_scene(), 320, 180);
  sim::RenderSettings settings;
  settings.noise_stddev = 0.0;
  CameraWorker worker(scene.camera, raster(scene, settings), recorder());
  const WallTime stamp = WallTime(std::chrono::seconds(1'800'000'000));
  std::vector<sim::ObjectPose> poses;
  for (const auto& object : scene.objects) poses.push_back({object.id, object.pose_world_object});
  worker.offer({poses, {}, stamp});
  ASSERT_TRUE(wait_frames(1));
  worker.offer({{}, {}, stamp + 1s});  // nothing in view: the background only
  ASSERT_TRUE(wait_frames(2));
  const std::lock_guard<std::mutex> lock(mutex_);
  EXPECT_EQ(sizes_[0], cv::Size(320, 180));
  EXPECT_EQ(stamps_[0], stamp);
  EXPECT_EQ(stamps_[1], stamp + 1s);
  EXPECT_NE(means_[0], means_[1]);  // the boxes changed the picture
  EXPECT_TRUE(depths_[0].empty());   // the rasteriser makes no depth image
  EXPECT_EQ(worker.frames(), 2u);
}

// A renderer that paints every frame one grey level.
class FlatRenderer final : public FrameRenderer {
 public:
  explicit FlatRenderer(int grey) : grey_(grey) {}
  void render(const CameraSnapshot&, const CameraDemand&, CameraImages& images) override {
    images.image_mono8 = cv::Mat(4, 4, CV_8UC1, cv::Scalar(grey_));
    images.depth_m.release();
  }

 private:
  int grey_;
};

// The cell's model built anew: the renderer made for it draws the next frame; one that cannot be made leaves
// the camera streaming with the old one.
TEST_F(CameraWorkerTest, AReplacedRendererDrawsTheNextFrameAndOneThatCannotBeMadeLeavesTheOld) {
  CameraWorker worker(
      cell_scene().camera, [] { return std::make_unique<FlatRenderer>(10); }, recorder());
  worker.offer(CameraSnapshot{});
  ASSERT_TRUE(wait_frames(1));
  worker.replace_renderer([] { return std::make_unique<FlatRenderer>(200); });
  worker.offer(CameraSnapshot{});
  ASSERT_TRUE(wait_frames(2));
  worker.replace_renderer([]() -> std::unique_ptr<FrameRenderer> { throw std::invalid_argument("no such scene"); });
  worker.offer(CameraSnapshot{});
  ASSERT_TRUE(wait_frames(3));
  const std::lock_guard<std::mutex> lock(mutex_);
  EXPECT_EQ(means_, (std::vector<double>{10.0, 200.0, 200.0}));
}

TEST_F(CameraWorkerTest, ARendererThatCannotStartFailsTheConstruction) {
  const sim::CameraScene scene = cell_scene();
  const RendererFactory no_gl = []() -> std::unique_ptr<FrameRenderer> {
    throw sim::GlUnavailableError("eglInitialize failed");
  };
  EXPECT_THROW(CameraWorker(scene.camera, no_gl, recorder()), sim::GlUnavailableError);
  EXPECT_THROW(CameraWorker(scene.camera, [] { return std::unique_ptr<FrameRenderer>(); }, recorder()),
               std::logic_error);
}

TEST_F(CameraWorkerTest, MujocoRendersThePhysicsStateOnItsOwnModelCopy) {
  const sim::CameraScene scene = resize_camera(cell_scene(), 320, 180);
  sim::CellPhysics physics(sim::load_cell_geometry(default_cell_file()));
  sim::MujocoCameraSettings settings;
  settings.noise_stddev = 0.0;
  CameraWorker worker(
      scene.camera, [&, model = physics.copy_model()] { return make_mujoco_renderer(model, scene, settings); },
      recorder());
  CameraSnapshot snapshot;
  snapshot.stamp = WallTime(std::chrono::seconds(1'800'000'000));
  physics.copy_kinematic_state(snapshot.state);
  worker.offer(snapshot);
  ASSERT_TRUE(wait_frames(1));
  // The crane's hook and the load hang from the bridge: move the bridge's joint far along and the
  // picture changes, although the physics (whose model the renderer copied) did not move.
  CameraSnapshot moved = snapshot;
  moved.stamp += 1s;
  for (double& q : moved.state.qpos) q += 0.3;
  worker.offer(moved);
  ASSERT_TRUE(wait_frames(2));
  const std::lock_guard<std::mutex> lock(mutex_);
  EXPECT_EQ(sizes_[0], cv::Size(320, 180));
  EXPECT_EQ(stamps_[1], snapshot.stamp + 1s);
  ASSERT_EQ(depths_[0].type(), CV_32FC1);
  EXPECT_EQ(depths_[0].size(), cv::Size(320, 180));
  double min_m = 0.0, max_m = 0.0;
  cv::minMaxIdx(depths_[0], &min_m, &max_m, nullptr, nullptr, depths_[0] == depths_[0]);  // finite pixels
  EXPECT_GT(min_m, 0.1);
  EXPECT_LT(max_m, 100.0);
  EXPECT_NE(means_[0], means_[1]);
}

TEST_F(CameraWorkerTest, RendersOnlyWhatIsReadAndNothingWhileNobodyReads) {
  const sim::CameraScene scene = resize_camera(cell_scene(), 320, 180);
  sim::CellPhysics physics(sim::load_cell_geometry(default_cell_file()));
  std::mutex asked_mutex;
  std::condition_variable asked_cv;
  int asked = 0;
  CameraDemand wanted{false, false};
  const CameraWorker::Demand demand = [&] {
    const std::lock_guard<std::mutex> lock(asked_mutex);
    ++asked;
    asked_cv.notify_all();
    return wanted;
  };
  const auto offer_and_wait_asked = [&](CameraWorker& worker, const CameraSnapshot& snapshot, CameraDemand next) {
    std::unique_lock<std::mutex> lock(asked_mutex);
    wanted = next;
    const int before = asked;
    lock.unlock();
    worker.offer(snapshot);
    lock.lock();
    return asked_cv.wait_for(lock, 10s, [&] { return asked > before; });
  };
  CameraWorker worker(
      scene.camera, [&, model = physics.copy_model()] { return make_mujoco_renderer(model, scene, {}); }, recorder(),
      demand);
  CameraSnapshot snapshot;
  physics.copy_kinematic_state(snapshot.state);
  snapshot.stamp = WallTime(std::chrono::seconds(1));
  ASSERT_TRUE(offer_and_wait_asked(worker, snapshot, {false, false}));  // nobody reads: not rendered
  snapshot.stamp = WallTime(std::chrono::seconds(2));
  ASSERT_TRUE(offer_and_wait_asked(worker, snapshot, {true, false}));
  ASSERT_TRUE(wait_frames(1));
  snapshot.stamp = WallTime(std::chrono::seconds(3));
  ASSERT_TRUE(offer_and_wait_asked(worker, snapshot, {false, true}));
  ASSERT_TRUE(wait_frames(2));
  const std::lock_guard<std::mutex> lock(mutex_);
  ASSERT_EQ(stamps_.size(), 2u);
  EXPECT_EQ(stamps_[0], WallTime(std::chrono::seconds(2)));
  EXPECT_TRUE(depths_[0].empty());  // the image alone: no depth resampled
  EXPECT_EQ(stamps_[1], WallTime(std::chrono::seconds(3)));
  EXPECT_EQ(depths_[1].type(), CV_32FC1);
  EXPECT_EQ(worker.frames(), 2u);
}

TEST_F(CameraWorkerTest, SnapshotsOfferedWhileBusyReplaceEachOther) {
  const sim::CameraScene scene = cell_scene();  // full size: slow enough to be busy
  CameraWorker worker(scene.camera, raster(scene), recorder());
  std::vector<sim::ObjectPose> poses;
  for (const auto& object : scene.objects) poses.push_back({object.id, object.pose_world_object});
  constexpr int kOffers = 20;
  for (int i = 0; i < kOffers; ++i) worker.offer({poses, {}, WallTime(std::chrono::seconds(i))});
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
