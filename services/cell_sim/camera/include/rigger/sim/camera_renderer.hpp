#pragma once
/// @file
/// The simulated camera's image renderer: a grey (mono8) image of the cell's boxed objects and
/// their ArUco markers as a pinhole camera at a given pose would see them. Pure C++ (OpenCV, Eigen):
/// no DDS, no logging. The ground truth of a frame is the poses it was rendered from.

#include "rigger/sim/camera_scene.hpp"
#include "rigger/sim/pixel_noise.hpp"

#include <Eigen/Geometry>
#include <opencv2/core.hpp>

#include <array>
#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <vector>

namespace rigger::sim {

/// How the scene looks. Radiances are fractions of full scale (1.0 = grey level 255).
struct RenderSettings {
  /// Gaussian pixel noise in grey levels; unset: the camera model's noise_stddev.
  std::optional<double> noise_stddev;
  /// Gaussian blur (optics, defocus) applied before the noise, in pixels; 0 disables it.
  double blur_sigma_px = 0.0;
  /// Samples per pixel edge when antialiasing faces and markers (area coverage); large polygons
  /// use fewer so a frame stays within a fixed budget of samples. Marker edges are what a tracker
  /// measures; face outlines are not.
  int face_supersampling = 2;
  int marker_supersampling = 2;
  double background = 0.22;
  /// Lambertian shading: ambient + (1 - ambient) * max(0, -n . light_direction).
  double ambient = 0.45;
  /// Direction the light travels, world frame (normalised internally).
  Eigen::Vector3d light_direction_world{0.0, 1.0, -1.0};
  /// Object albedo by object id; default_albedo for the others.
  std::map<std::string, double> albedo;
  double default_albedo = 0.5;
  /// Reflectance of the marker print.
  double marker_white = 0.92;
  double marker_black = 0.05;
  /// Seed of the noise generator (a renderer is deterministic for a given seed and call sequence).
  /// The noise of a frame is a window at a random offset into a bank of a few frames' worth of
  /// samples drawn at the first noisy frame: independent within a frame, different in every frame.
  std::uint64_t seed = 1;
};

/// The world pose of one object of the scene, by id.
struct ObjectPose {
  std::string object_id;
  Eigen::Isometry3d pose_world_object = Eigen::Isometry3d::Identity();
};

/// How one marker appears in the image (pinhole projection, no noise): for ground truth, test
/// fixtures and choosing views.
struct MarkerView {
  std::string object_id;
  int marker_id = 0;
  /// The printed marker's outer corners in OpenCV ArUco order (top-left, top-right, bottom-right,
  /// bottom-left of the printed image), pixels.
  std::array<Eigen::Vector2d, 4> corners_px{};
  /// The marker's face points towards the camera.
  bool front_facing = false;
  /// Fraction of a 5 x 5 grid over the marker and its quiet zone that is in the image, in front of
  /// the camera and not hidden by another object. 1 = fully visible.
  double visible_fraction = 0.0;
  /// Angle between the marker's normal and the line of sight to its centre, radians.
  double viewing_angle_rad = 0.0;
  /// Distance from the camera centre to the marker centre, metres.
  double distance_m = 0.0;
};

/// Outcome of a render call (nothing throws once the renderer is built).
enum class RenderStatus {
  kOk,
  /// A pose named an object the scene does not have; it was skipped, the rest was drawn.
  kUnknownObject,
  /// A pose (camera or object) was not finite; nothing was drawn but the background.
  kInvalidPose,
  /// The OpenGL context could not be made current (MujocoCamera only); the frame is unchanged.
  kGlError,
};

/// Renders grey images of boxed objects with ArUco markers: flat-shaded visible faces (back faces
/// culled, objects in painter's order from a separating-axis test, so one object correctly hides
/// another), and markers drawn with cv::aruco::drawMarker, a white quiet zone of one module around
/// each, mapped onto their face plane by an exact homography and antialiased by area sampling
/// (corner positions agree with the pinhole projection to a few hundredths of a pixel).
/// Not thread safe: one renderer per thread. Objects that interpenetrate are ordered by distance,
/// which can be wrong where they overlap.
class CameraRenderer {
 public:
  /// Throws std::invalid_argument for a camera without a size or focal length, non-zero lens
  /// distortion (not supported), an unknown dictionary id or unusable settings.
  CameraRenderer(CameraModel camera, std::vector<BoxObject> objects, int dictionary, RenderSettings settings = {});
  /// Convenience: the camera, objects and dictionary of a scene.
  explicit CameraRenderer(const CameraScene& scene, RenderSettings settings = {});

  /// Renders the objects listed in poses (others are not drawn) seen from pose_world_camera
  /// (optical frame: z forward, x right, y down) into image_mono8 (CV_8UC1, width x height).
  RenderStatus render(const Eigen::Isometry3d& pose_world_camera, const std::vector<ObjectPose>& poses,
                      cv::Mat& image_mono8);

  /// The markers of the listed objects as the camera would see them, noise-free.
  std::vector<MarkerView> marker_views(const Eigen::Isometry3d& pose_world_camera,
                                       const std::vector<ObjectPose>& poses) const;

  const CameraModel& camera() const { return camera_; }
  const std::vector<BoxObject>& objects() const { return objects_; }

 private:
  struct Face {
    std::array<Eigen::Vector3d, 4> corners_object;
    Eigen::Vector3d normal_object;
    std::vector<std::size_t> markers;
  };
  struct ObjectData {
    std::array<Face, 6> faces;
    double albedo = 0.5;
  };
  struct Placed {
    std::size_t index;
    Eigen::Isometry3d pose_camera_object;
  };

  std::vector<std::size_t> painter_order(const std::vector<Placed>& placed) const;
  void draw_face(const Placed& object, const Face& face, const Eigen::Isometry3d& pose_world_camera);
  void draw_polygon(const std::vector<Eigen::Vector3d>& corners_camera, double radiance);
  void draw_marker(const BoxObject& object, std::size_t marker_index, const Eigen::Isometry3d& pose_camera_object,
                   double light);
  bool occluded(const std::vector<Placed>& placed, std::size_t self, const Eigen::Vector3d& point_camera) const;
  Eigen::Vector2d project(const Eigen::Vector3d& point_camera) const;

  CameraModel camera_;
  std::vector<BoxObject> objects_;
  RenderSettings settings_;
  double noise_stddev_ = 0.0;
  std::vector<ObjectData> data_;
  /// Per object, per marker, per magnification (1, 2, 4 ... texels per module): the printed marker
  /// with its quiet zone; channel 0 the print, channel 1 all 255 (warped into the marker's
  /// coverage). CV_8UC2.
  std::vector<std::vector<std::vector<cv::Mat>>> marker_textures_;
  cv::Mat canvas_;  // CV_32FC1 radiance in grey levels
  cv::Mat scratch_a_;
  cv::Mat scratch_b_;
  PixelNoise noise_{0.0, 1};
};

}  // namespace rigger::sim
