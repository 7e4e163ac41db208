#include "camera_worker.hpp"

#include <cmath>
#include <stdexcept>
#include <string>

namespace rigger::cell_sim {

sim::CameraScene resize_camera(sim::CameraScene scene, int width_px, int height_px) {
  if (width_px <= 0 && height_px <= 0) return scene;
  auto& c = scene.camera;
  const double sx = static_cast<double>(width_px) / c.width_px;
  const double sy = static_cast<double>(height_px) / c.height_px;
  // A different aspect ratio would need a crop, not a scale: refuse it rather than distort.
  if (width_px <= 0 || height_px <= 0 || std::abs(sx - sy) > 0.01 * sx) {
    throw std::invalid_argument("camera size " + std::to_string(width_px) + "x" + std::to_string(height_px) +
                                " does not keep the aspect ratio of " + std::to_string(c.width_px) + "x" +
                                std::to_string(c.height_px));
  }
  // Pixel centres: (0, 0) is the centre of the top-left pixel, so the principal point scales about
  // the image's corner at (-0.5, -0.5).
  c.fx_px *= sx;
  c.fy_px *= sy;
  c.cx_px = (c.cx_px + 0.5) * sx - 0.5;
  c.cy_px = (c.cy_px + 0.5) * sy - 0.5;
  c.width_px = width_px;
  c.height_px = height_px;
  return scene;
}

CameraWorker::CameraWorker(const sim::CameraScene& scene, sim::RenderSettings settings, OnFrame on_frame)
    : camera_(scene.camera),
      pose_world_camera_(scene.pose_world_camera),
      renderer_(scene, std::move(settings)),
      on_frame_(std::move(on_frame)) {
  thread_ = std::thread([this] { run(); });
}

CameraWorker::~CameraWorker() {
  {
    const std::lock_guard<std::mutex> lock(mutex_);
    stop_ = true;
  }
  wake_.notify_all();
  thread_.join();
}

void CameraWorker::offer(CameraSnapshot snapshot) {
  {
    const std::lock_guard<std::mutex> lock(mutex_);
    if (pending_) ++dropped_;
    pending_ = std::move(snapshot);
  }
  wake_.notify_one();
}

void CameraWorker::run() {
  cv::Mat image;
  for (;;) {
    CameraSnapshot snapshot;
    {
      std::unique_lock<std::mutex> lock(mutex_);
      wake_.wait(lock, [this] { return stop_ || pending_.has_value(); });
      if (stop_) return;
      snapshot = std::move(*pending_);
      pending_.reset();
    }
    // A pose the renderer does not know or cannot use still yields a frame (the background, or the
    // objects it knows): a camera keeps streaming, and the tracker judges what it sees.
    renderer_.render(pose_world_camera_, snapshot.poses, image);
    ++frames_;
    if (on_frame_) on_frame_(image, snapshot.stamp);
  }
}

}  // namespace rigger::cell_sim
