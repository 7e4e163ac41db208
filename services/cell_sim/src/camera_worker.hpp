#pragma once
/// @file
/// The simulated camera's thread: renders the cell from the state the physics thread hands it, so
/// that rendering never slows the physics. What renders is a FrameRenderer made on the camera
/// thread itself (an OpenGL context belongs to the thread that made it; camera_renderers.hpp). No
/// DDS: the frame goes to a callback (the node publishes it).

#include <atomic>
#include <condition_variable>
#include <cstdint>
#include <functional>
#include <memory>
#include <mutex>
#include <optional>
#include <thread>

#include <opencv2/core.hpp>

#include "rigger/base/time.hpp"
#include "rigger/sim/camera_renderer.hpp"
#include "rigger/sim/camera_scene.hpp"
#include "rigger/sim/cell_physics.hpp"

namespace rigger::cell_sim {

/// What the camera should see: one physics step's object poses (for the markers) and joint and
/// mocap positions (for a renderer with its own copy of the model), and when that step happened.
struct CameraSnapshot {
  std::vector<sim::ObjectPose> poses;  ///< world frame
  sim::KinematicState state;           ///< empty for a renderer that draws from the poses only
  WallTime stamp{};                    ///< wall time of the physics step (the image's exposure time)
};

/// What the frame is for: the images somebody reads. Nobody reading either: the frame is not rendered
/// (an unwatched MuJoCo camera would cost most of a core for nothing).
struct CameraDemand {
  bool image = true;
  bool depth = true;  ///< a renderer without depth ignores it
};

/// One rendered frame.
struct CameraImages {
  cv::Mat image_mono8;  ///< CV_8UC1, the camera's size
  /// CV_32FC1 metres along the optical axis, NaN where nothing was seen; empty when the renderer
  /// makes no depth image.
  cv::Mat depth_m;
};

/// Renders frames on the camera thread. Nothing throws in render(): a pose it cannot use still
/// yields a frame (the background, or what it knows), since a camera keeps streaming and the
/// tracker judges what it sees.
class FrameRenderer {
 public:
  virtual ~FrameRenderer() = default;
  /// Fills images.image_mono8, and images.depth_m when `demand.depth` and the renderer makes depth
  /// (otherwise depth_m is empty).
  virtual void render(const CameraSnapshot& snapshot, const CameraDemand& demand, CameraImages& images) = 0;
};

/// Makes the renderer, called once on the camera thread. May throw (its error fails the worker's
/// construction).
using RendererFactory = std::function<std::unique_ptr<FrameRenderer>()>;

/// The scene as configured, with the image size changed to `width` x `height` (0: unchanged) and the
/// intrinsics scaled with it. @throws std::invalid_argument for a size of another aspect ratio.
sim::CameraScene resize_camera(sim::CameraScene scene, int width_px, int height_px);

/// Renders on a thread of its own. offer() never blocks: a snapshot that arrives while a frame is
/// being rendered replaces the waiting one, and the replaced one counts as dropped. Before each frame
/// the worker asks `demand` what is read; a frame nobody reads is skipped (and counted as neither).
/// Thread safety: offer(), frames() and dropped() from any thread; on_frame and demand run on the
/// camera thread.
class CameraWorker {
 public:
  using OnFrame = std::function<void(const CameraImages& images, WallTime stamp)>;
  using Demand = std::function<CameraDemand()>;

  /// Starts the thread and makes the renderer there; returns once it is made. Without `demand`,
  /// every frame is rendered with depth.
  /// @throws whatever make_renderer throws (the thread is joined first).
  CameraWorker(const sim::CameraModel& camera, RendererFactory make_renderer, OnFrame on_frame, Demand demand = {});
  ~CameraWorker();
  CameraWorker(const CameraWorker&) = delete;
  CameraWorker& operator=(const CameraWorker&) = delete;

  void offer(CameraSnapshot snapshot);
  /// Renders the frames of snapshots offered from now on with a renderer `make_renderer` makes on the
  /// camera thread before the next frame (the cell's model was built anew). A factory that throws leaves the
  /// current renderer on (the factory reports its own error). Thread-safe; never blocks on a frame.
  void replace_renderer(RendererFactory make_renderer);
  std::uint64_t frames() const { return frames_.load(); }
  std::uint64_t dropped() const { return dropped_.load(); }
  const sim::CameraModel& camera() const { return camera_; }

 private:
  void run(const RendererFactory& make_renderer, std::exception_ptr& start_error);

  sim::CameraModel camera_;
  OnFrame on_frame_;
  Demand demand_;
  std::mutex mutex_;
  std::condition_variable wake_;
  std::optional<CameraSnapshot> pending_;
  RendererFactory pending_renderer_;  ///< made before the next frame
  bool started_ = false;
  bool stop_ = false;
  std::atomic<std::uint64_t> frames_{0};
  std::atomic<std::uint64_t> dropped_{0};
  std::thread thread_;  // last: started after everything it uses
};

}  // namespace rigger::cell_sim
