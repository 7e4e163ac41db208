#pragma once
/// @file
/// The simulated camera's thread: renders a grey image of the load and the target from the poses
/// the physics thread hands it, so that rendering never slows the physics. No DDS: the frame goes
/// to a callback (the node publishes it).

#include <atomic>
#include <condition_variable>
#include <cstdint>
#include <functional>
#include <mutex>
#include <optional>
#include <thread>

#include <opencv2/core.hpp>

#include "rigger/base/time.hpp"
#include "rigger/sim/camera_renderer.hpp"
#include "rigger/sim/camera_scene.hpp"

namespace rigger::cell_sim {

/// What the camera should see: the object poses of one physics step and when that step happened.
struct CameraSnapshot {
  std::vector<sim::ObjectPose> poses;  ///< world frame
  WallTime stamp{};                    ///< wall time of the physics step (the image's exposure time)
};

/// The scene as configured, with the image size changed to `width` x `height` (0: unchanged) and the
/// intrinsics scaled with it. @throws std::invalid_argument for a size of another aspect ratio.
sim::CameraScene resize_camera(sim::CameraScene scene, int width_px, int height_px);

/// Renders on a thread of its own. offer() never blocks: a snapshot that arrives while a frame is
/// being rendered replaces the waiting one, and the replaced one counts as dropped.
/// Thread safety: offer(), frames() and dropped() from any thread; on_frame runs on the camera thread.
class CameraWorker {
 public:
  using OnFrame = std::function<void(const cv::Mat& image_mono8, WallTime stamp)>;

  /// @throws std::invalid_argument (bad camera or settings, from CameraRenderer).
  CameraWorker(const sim::CameraScene& scene, sim::RenderSettings settings, OnFrame on_frame);
  ~CameraWorker();
  CameraWorker(const CameraWorker&) = delete;
  CameraWorker& operator=(const CameraWorker&) = delete;

  void offer(CameraSnapshot snapshot);
  std::uint64_t frames() const { return frames_.load(); }
  std::uint64_t dropped() const { return dropped_.load(); }
  const sim::CameraModel& camera() const { return camera_; }
  const Eigen::Isometry3d& pose_world_camera() const { return pose_world_camera_; }

 private:
  void run();

  sim::CameraModel camera_;
  Eigen::Isometry3d pose_world_camera_;
  sim::CameraRenderer renderer_;
  OnFrame on_frame_;
  std::mutex mutex_;
  std::condition_variable wake_;
  std::optional<CameraSnapshot> pending_;
  bool stop_ = false;
  std::atomic<std::uint64_t> frames_{0};
  std::atomic<std::uint64_t> dropped_{0};
  std::thread thread_;  // last: started after everything it uses
};

}  // namespace rigger::cell_sim
