#include "camera_worker.hpp"

#include <cmath>
#include <exception>
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

CameraWorker::CameraWorker(const sim::CameraModel& camera, RendererFactory make_renderer, OnFrame on_frame,
                           Demand demand)
    : camera_(camera), on_frame_(std::move(on_frame)), demand_(std::move(demand)) {
  std::exception_ptr start_error;
  thread_ = std::thread([this, &make_renderer, &start_error] { run(make_renderer, start_error); });
  std::unique_lock<std::mutex> lock(mutex_);
  wake_.wait(lock, [this] { return started_; });
  if (start_error) {
    lock.unlock();
    thread_.join();
    std::rethrow_exception(start_error);
  }
}

CameraWorker::~CameraWorker() {
  {
    const std::lock_guard<std::mutex> lock(mutex_);
    stop_ = true;
  }
  wake_.notify_all();
  if (thread_.joinable()) thread_.join();
}

void CameraWorker::offer(CameraSnapshot snapshot) {
  {
    const std::lock_guard<std::mutex> lock(mutex_);
    if (pending_) ++dropped_;
    pending_ = std::move(snapshot);
  }
  wake_.notify_all();
}

void CameraWorker::replace_renderer(RendererFactory make_renderer) {
  const std::lock_guard<std::mutex> lock(mutex_);
  pending_renderer_ = std::move(make_renderer);
}

void CameraWorker::run(const RendererFactory& make_renderer, std::exception_ptr& start_error) {
  // The renderer is made here, not by the constructor's thread: an OpenGL context is current on
  // the thread that made it, and MuJoCo's renderer draws with the current one.
  std::unique_ptr<FrameRenderer> renderer;
  try {
    renderer = make_renderer();
  } catch (...) {
    start_error = std::current_exception();
  }
  if (!renderer && !start_error) {
    start_error = std::make_exception_ptr(std::logic_error("camera: the renderer factory made no renderer"));
  }
  {
    const std::lock_guard<std::mutex> lock(mutex_);
    started_ = true;
  }
  wake_.notify_all();
  if (!renderer) return;

  CameraImages images;
  for (;;) {
    CameraSnapshot snapshot;
    RendererFactory make_next;
    {
      std::unique_lock<std::mutex> lock(mutex_);
      wake_.wait(lock, [this] { return stop_ || pending_.has_value(); });
      if (stop_) return;
      snapshot = std::move(*pending_);
      pending_.reset();
      make_next.swap(pending_renderer_);
    }
    if (make_next) {
      // Made before the old one goes, so that a renderer that cannot be made leaves the camera streaming
      // (each MuJoCo renderer makes its own EGL context current for every frame).
      try {
        std::unique_ptr<FrameRenderer> next = make_next();
        if (next) renderer = std::move(next);
      } catch (const std::exception&) {
        // The factory's caller hears of it from the factory; the camera goes on with what it has.
      }
    }
    const CameraDemand demand = demand_ ? demand_() : CameraDemand{};
    if (!demand.image && !demand.depth) continue;
    renderer->render(snapshot, demand, images);
    ++frames_;
    if (on_frame_) on_frame_(images, snapshot.stamp);
  }
}

}  // namespace rigger::cell_sim
