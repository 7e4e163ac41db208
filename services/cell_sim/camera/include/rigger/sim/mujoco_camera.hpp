#pragma once
/// @file
/// The simulated camera rendered by MuJoCo: what the physics model holds (meshes and primitives,
/// lit and shaded by MuJoCo's OpenGL renderer, headless through EGL), seen through the cell file's
/// intrinsics and lens distortion, with the cell file's ArUco markers on their objects and a depth
/// image beside the grey one.
///
/// How: MuJoCo renders an ideal pinhole image (square pixels, centred principal point, a field of
/// view just covering the distorted image) with its depth buffer; the markers are drawn into it as
/// decals (homography onto the face plane, depth-tested, shaded with the face's rendered
/// brightness); one precomputed map then resamples colour and depth to the
/// target intrinsics and distortion (depth interpolated within a surface, never across an edge).

#include <mujoco/mujoco.h>

#include <opencv2/core.hpp>

#include <Eigen/Geometry>

#include <cstdint>
#include <memory>
#include <optional>
#include <vector>

#include "rigger/sim/camera_renderer.hpp"
#include "rigger/sim/camera_scene.hpp"
#include "rigger/sim/depth_noise.hpp"
#include "rigger/sim/egl_context.hpp"
#include "rigger/sim/pixel_noise.hpp"

namespace rigger::sim {

namespace detail {
class LensMap;
class MarkerDecals;
}  // namespace detail

/// How the MuJoCo camera renders.
struct MujocoCameraSettings {
  /// Also fill CameraFrame::image_rgb8 (the grey image is always made).
  bool colour = false;
  /// Reflectance of the marker print (fractions of the face's light).
  double marker_white = 0.92;
  double marker_black = 0.05;
  /// Gaussian noise added to the grey image, grey levels; unset: the camera model's noise_stddev.
  std::optional<double> noise_stddev;
  /// Seed of the noise (see PixelNoise).
  std::uint64_t seed = 1;
  /// Largest side of the intermediate pinhole render, pixels (its focal length is lowered to fit).
  int max_render_px = 4096;
  /// What a structured-light sensor does to the depth image (none by default: the perfect depth).
  DepthNoiseSettings depth_noise;
};

/// One rendered frame.
struct CameraFrame {
  /// CV_8UC1, width x height of the camera: the grey image the camera topic carries, with the
  /// pixel noise.
  cv::Mat image_mono8;
  /// CV_8UC3 RGB, only with MujocoCameraSettings::colour (no noise); empty otherwise.
  cv::Mat image_rgb8;
  /// CV_32FC1: z of the point seen in the optical frame (metres along the optical axis, not along
  /// the ray); NaN where nothing was seen (background, beyond MuJoCo's far plane).
  cv::Mat depth_m;
  /// Markers drawn (facing the camera, in front of the near plane, on a surface of the model);
  /// parts of them may still be hidden.
  int markers_drawn = 0;
};

/// Renders camera frames of a MuJoCo model. Owns its EGL context: construct it on the thread that
/// renders and render only there (one camera per thread; not thread safe). The model must outlive
/// the camera and keep its meshes, textures and materials (they are uploaded once).
class MujocoCamera {
 public:
  /// @param model      any compiled model; its offscreen buffer size is not used (the camera sizes
  ///                   its own), its znear/zfar (vis.map, times stat.extent) are the clipping planes
  /// @param camera     the cell file's intrinsics and 0, 4 or 5 plumb_bob distortion coefficients
  /// @param objects    the objects whose markers are drawn (their boxes come from the model)
  /// @param dictionary OpenCV predefined ArUco dictionary id of the markers
  /// @throws GlUnavailableError without EGL or OpenGL; std::invalid_argument for a bad camera,
  ///         dictionary, marker or settings.
  MujocoCamera(const mjModel& model, const CameraModel& camera, std::vector<BoxObject> objects, int dictionary,
               MujocoCameraSettings settings = {});
  /// Convenience: the camera, objects and dictionary of a cell file's scene.
  MujocoCamera(const mjModel& model, const CameraScene& scene, MujocoCameraSettings settings = {});
  ~MujocoCamera();
  MujocoCamera(const MujocoCamera&) = delete;
  MujocoCamera& operator=(const MujocoCamera&) = delete;

  /// Renders `data` (positions up to date: after mj_forward or mj_step; only read, though MuJoCo's
  /// scene update takes it mutable) seen from pose_world_camera (optical frame: z forward, x right,
  /// y down), with the markers of the objects listed in `poses`. Nothing throws: kInvalidPose for
  /// a non-finite pose (frame left unchanged), kUnknownObject when a pose names an object without
  /// markers here (the rest is drawn), kGlError when the context cannot be made current.
  /// Without `depth`, frame.depth_m is left empty (its resampling is a third of a frame's time).
  RenderStatus render(mjData& data, const Eigen::Isometry3d& pose_world_camera, const std::vector<ObjectPose>& poses,
                      CameraFrame& frame, bool depth = true);

  /// The last rendered grey image again, with fresh pixel noise, and nothing else of `frame`
  /// changed: for a scene that has not moved (a real camera's images of a still scene differ by
  /// their noise alone). False before the first render.
  bool repeat(CameraFrame& frame);

  const CameraModel& camera() const { return camera_; }
  /// The intermediate pinhole render's size and focal length (pixels).
  cv::Size render_size() const;
  double render_focal_px() const;
  /// The OpenGL renderer in use (e.g. "llvmpipe ...").
  const char* gl_renderer() const { return gl_.renderer(); }

 private:
  EglContext gl_;  // first: destroyed last, after MuJoCo's GL objects
  const mjModel* model_;
  CameraModel camera_;
  MujocoCameraSettings settings_;
  std::vector<std::string> object_ids_;
  std::unique_ptr<detail::LensMap> lens_;
  std::unique_ptr<detail::MarkerDecals> decals_;
  mjvScene scene_{};
  mjrContext context_{};
  mjvOption option_{};
  mjvCamera free_camera_{};
  cv::Mat render_rgb_;    // CV_8UC3, rows bottom-up
  cv::Mat render_depth_;  // CV_32FC1 window depth
  cv::Mat render_grey_;
  cv::Mat clean_mono8_;  // the last grey image at the camera's size, before the noise
  PixelNoise noise_;
  DepthNoise depth_noise_;
};

}  // namespace rigger::sim
