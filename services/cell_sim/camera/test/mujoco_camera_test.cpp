// MuJoCo's render through the cell file's camera, checked against geometry computed here: the depth
// of a tilted plate, ArUco markers detected in a distorted image against cv::projectPoints, and a
// box's silhouette against ray casting. Real rendering (EGL, llvmpipe on a machine without a GPU).
#include "rigger/sim/mujoco_camera.hpp"

#include <gtest/gtest.h>
#include <opencv2/aruco.hpp>
#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>

#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include "rigger/testing/require.hpp"

namespace rigger::sim {
namespace {

struct ModelDeleter {
  void operator()(mjModel* m) const { mj_deleteModel(m); }
};
struct DataDeleter {
  void operator()(mjData* d) const { mj_deleteData(d); }
};

/// A static MuJoCo scene of boxes (no joints), positions computed.
struct Scene {
  std::unique_ptr<mjModel, ModelDeleter> model;
  std::unique_ptr<mjData, DataDeleter> data;
};

struct SceneBox {
  Eigen::Isometry3d pose_world_box;
  Eigen::Vector3d half_m;
  std::string rgba = "0.8 0.8 0.8 1";
};

Scene make_scene(const std::vector<SceneBox>& boxes) {
  std::ostringstream xml;
  xml << "<mujoco><visual><headlight ambient='0.35 0.35 0.35' diffuse='0.55 0.55 0.55' specular='0 0 0'/>"
         "</visual><worldbody>";
  for (const SceneBox& box : boxes) {
    const Eigen::Quaterniond q(box.pose_world_box.linear());
    const Eigen::Vector3d& p = box.pose_world_box.translation();
    xml.precision(17);
    xml << "<body pos='" << p.x() << ' ' << p.y() << ' ' << p.z() << "' quat='" << q.w() << ' ' << q.x() << ' ' << q.y()
        << ' ' << q.z() << "'><geom type='box' size='" << box.half_m.x() << ' ' << box.half_m.y() << ' '
        << box.half_m.z() << "' rgba='" << box.rgba << "'/></body>";
  }
  xml << "</worldbody></mujoco>";
  const std::filesystem::path path =
      std::filesystem::temp_directory_path() / ("rigger_mujoco_camera_test_" + std::to_string(::getpid()) + ".xml");
  std::ofstream(path) << xml.str();
  char error[1000] = "";
  Scene scene;
  scene.model.reset(mj_loadXML(path.c_str(), nullptr, error, sizeof error));
  std::filesystem::remove(path);
  if (!scene.model) {
    ADD_FAILURE() << "MJCF: " << error;
    return scene;
  }
  scene.data.reset(mj_makeData(scene.model.get()));
  mj_forward(scene.model.get(), scene.data.get());
  return scene;
}

const std::vector<double> kDistortion = {-0.2, 0.05, 0.001, -0.001, 0.0};

CameraModel camera_640() {
  CameraModel camera = CameraModel::pinhole(640, 480, 500.0, 322.0, 236.0);
  camera.fy_px = 503.0;
  camera.distortion = kDistortion;
  return camera;
}

// The camera is placed off the world origin with a roll, so that the optical frame's handling
// (MuJoCo's free camera cannot roll) is part of every check.
Eigen::Isometry3d camera_pose() {
  return Eigen::Translation3d(0.3, -0.2, 0.1) * Eigen::AngleAxisd(0.2, Eigen::Vector3d::UnitY()) *
         Eigen::AngleAxisd(0.17, Eigen::Vector3d::UnitZ()) * Eigen::Isometry3d::Identity();
}

/// The ray (z = 1, optical frame) of every pixel, from cv::undistortPoints.
cv::Mat pixel_rays(const CameraModel& camera) {
  std::vector<cv::Point2d> pixels;
  for (int v = 0; v < camera.height_px; ++v) {
    for (int u = 0; u < camera.width_px; ++u) {
      pixels.emplace_back(u, v);
    }
  }
  const cv::Matx33d k(camera.fx_px, 0, camera.cx_px, 0, camera.fy_px, camera.cy_px, 0, 0, 1);
  std::vector<cv::Point2d> rays;
  cv::undistortPoints(pixels, rays, k, camera.distortion, cv::noArray(), cv::noArray(),
                      cv::TermCriteria(cv::TermCriteria::COUNT | cv::TermCriteria::EPS, 200, 1e-14));
  return cv::Mat(rays, true).reshape(2, camera.height_px);
}

/// Mean and standard deviation of `a - b` where `b` is unsaturated (grey within 21..234), in grey
/// levels; {NaN, NaN} (failing any bound) when fewer than 10000 such pixels are left.
std::pair<double, double> difference_stats(const cv::Mat& a, const cv::Mat& b) {
  cv::Mat difference;
  cv::subtract(a, b, difference, cv::noArray(), CV_32F);
  const cv::Mat unsaturated = (b > 20) & (b < 235);
  if (cv::countNonZero(unsaturated) < 10000) {
    return {std::nan(""), std::nan("")};
  }
  cv::Scalar mean;
  cv::Scalar stddev;
  cv::meanStdDev(difference, mean, stddev, unsaturated);
  return {mean[0], stddev[0]};
}

class MujocoCameraTest : public ::testing::Test {
 protected:
  /// The camera, or nullptr with gl_error_ set when this machine has no headless OpenGL.
  std::unique_ptr<MujocoCamera> make_camera(const Scene& scene, const CameraModel& camera,
                                            std::vector<BoxObject> objects = {}) {
    try {
      return std::make_unique<MujocoCamera>(*scene.model, camera, std::move(objects), cv::aruco::DICT_4X4_50);
    } catch (const GlUnavailableError& e) {
      gl_error_ = e.what();
      return nullptr;
    }
  }
  std::string gl_error_;
};

TEST_F(MujocoCameraTest, DepthOfATiltedPlateIsWithinAMillimetreAndNanBesideIt) {
  const Eigen::Vector3d half(0.8, 0.6, 0.004);
  const Eigen::Isometry3d pose_camera_box =
      Eigen::Translation3d(0.1, -0.05, 2.5) * Eigen::AngleAxisd(0.5, Eigen::Vector3d::UnitY()) *
      Eigen::AngleAxisd(0.25, Eigen::Vector3d::UnitX()) * Eigen::Isometry3d::Identity();
  const Scene scene = make_scene({{camera_pose() * pose_camera_box, half}});
  ASSERT_TRUE(scene.model);
  const CameraModel model = camera_640();
  auto camera = make_camera(scene, model);
  RIGGER_REQUIRE_OR_SKIP(camera != nullptr, gl_error_);
  CameraFrame frame;
  ASSERT_EQ(camera->render(*scene.data, camera_pose(), {}, frame), RenderStatus::kOk);
  ASSERT_EQ(frame.depth_m.type(), CV_32FC1);
  ASSERT_EQ(frame.depth_m.size(), cv::Size(640, 480));

  // The face towards the camera, and where each pixel's ray meets its plane.
  const Eigen::Matrix3d r = pose_camera_box.linear();
  const Eigen::Vector3d& c = pose_camera_box.translation();
  const Eigen::Vector3d normal = r.col(2).dot(c) < 0.0 ? Eigen::Vector3d(r.col(2)) : Eigen::Vector3d(-r.col(2));
  const Eigen::Vector3d on_face = c + half.z() * normal;
  const cv::Mat rays = pixel_rays(model);
  int seen = 0;
  int empty = 0;
  double worst_m = 0.0;
  for (int v = 0; v < model.height_px; ++v) {
    for (int u = 0; u < model.width_px; ++u) {
      const cv::Vec2d n = rays.at<cv::Vec2d>(v, u);
      const Eigen::Vector3d ray(n[0], n[1], 1.0);
      const double z = normal.dot(on_face) / normal.dot(ray);
      const Eigen::Vector3d in_box = r.transpose() * (z * ray - c);
      // Two pixels from the outline either way: the outline itself is a matter of sampling.
      const double margin_m = 2.0 * z / model.fx_px;
      const double out_x = std::abs(in_box.x()) - half.x();
      const double out_y = std::abs(in_box.y()) - half.y();
      const float depth = frame.depth_m.at<float>(v, u);
      if (out_x < -margin_m && out_y < -margin_m) {
        ++seen;
        ASSERT_TRUE(std::isfinite(depth)) << "pixel " << u << "," << v;
        worst_m = std::max(worst_m, std::abs(depth - z));
      } else if (out_x > margin_m || out_y > margin_m) {
        ++empty;
        EXPECT_TRUE(std::isnan(depth)) << "pixel " << u << "," << v << " depth " << depth;
      }
    }
  }
  EXPECT_GT(seen, 50000);
  EXPECT_GT(empty, 50000);
  EXPECT_LT(worst_m, 1e-3);
}

TEST_F(MujocoCameraTest, MarkersThroughDistortionLandWhereProjectPointsSays) {
  CameraModel model = CameraModel::pinhole(1280, 960, 1000.0, 645.0, 475.0);
  model.fy_px = 1005.0;
  model.distortion = kDistortion;
  // Boxes of 0.3 m with a 0.15 m marker on the face towards the camera: at the centre, towards two
  // corners (where the distortion is strongest), and one behind a plate that hides it.
  const Eigen::Vector3d half(0.15, 0.15, 0.05);
  const Eigen::Isometry3d facing = Eigen::Isometry3d(Eigen::AngleAxisd(M_PI, Eigen::Vector3d::UnitX()));
  const std::vector<Eigen::Isometry3d> pose_camera_boxes = {
      Eigen::Translation3d(0.0, 0.0, 1.2) * Eigen::AngleAxisd(0.3, Eigen::Vector3d::UnitY()) * facing,
      Eigen::Translation3d(-0.55, -0.38, 1.25) * Eigen::AngleAxisd(-0.2, Eigen::Vector3d::UnitX()) * facing,
      Eigen::Translation3d(0.52, 0.36, 1.15) * Eigen::AngleAxisd(0.4, Eigen::Vector3d::UnitZ()) * facing,
      Eigen::Translation3d(0.5, -0.3, 1.6) * facing};
  const Eigen::Isometry3d pose_camera_plate = Eigen::Translation3d(0.5, -0.3, 1.3) * facing;
  std::vector<SceneBox> boxes;
  std::vector<BoxObject> objects;
  std::vector<ObjectPose> poses;
  for (std::size_t i = 0; i < pose_camera_boxes.size(); ++i) {
    const Eigen::Isometry3d pose_world_box = camera_pose() * pose_camera_boxes[i];
    boxes.push_back({pose_world_box, half, "0.6 0.6 0.6 1"});
    BoxObject object;
    object.id = "box" + std::to_string(i);
    object.size_m = 2.0 * half;
    object.markers.push_back({static_cast<int>(i) + 1, 0.15, Eigen::Isometry3d(Eigen::Translation3d(0, 0, half.z()))});
    objects.push_back(object);
    poses.push_back({object.id, pose_world_box});
  }
  boxes.push_back({camera_pose() * pose_camera_plate, Eigen::Vector3d(0.2, 0.2, 0.01), "0.3 0.5 0.3 1"});
  const Scene scene = make_scene(boxes);
  ASSERT_TRUE(scene.model);
  auto camera = make_camera(scene, model, objects);
  RIGGER_REQUIRE_OR_SKIP(camera != nullptr, gl_error_);
  CameraFrame frame;
  ASSERT_EQ(camera->render(*scene.data, camera_pose(), poses, frame), RenderStatus::kOk);
  EXPECT_EQ(frame.markers_drawn, 4);  // the hidden one is drawn, and fails its depth test everywhere

  const cv::Ptr<cv::aruco::Dictionary> dictionary = cv::aruco::getPredefinedDictionary(cv::aruco::DICT_4X4_50);
  const cv::Ptr<cv::aruco::DetectorParameters> parameters = cv::aruco::DetectorParameters::create();
  parameters->cornerRefinementMethod = cv::aruco::CORNER_REFINE_SUBPIX;
  std::vector<std::vector<cv::Point2f>> corners;
  std::vector<int> ids;
  cv::aruco::detectMarkers(frame.image_mono8, dictionary, corners, ids, parameters);

  const cv::Matx33d k(model.fx_px, 0, model.cx_px, 0, model.fy_px, model.cy_px, 0, 0, 1);
  int found = 0;
  for (std::size_t i = 0; i < ids.size(); ++i) {
    ASSERT_GE(ids[i], 1);
    ASSERT_LE(ids[i], 3) << "marker " << ids[i] << " is behind the plate and must stay hidden";
    ++found;
    const Eigen::Isometry3d pose_camera_marker =
        pose_camera_boxes[ids[i] - 1] * objects[ids[i] - 1].markers[0].pose_object_marker;
    std::vector<cv::Point3d> corners_camera;
    for (const auto& [x, y] : {std::pair{-1.0, 1.0}, {1.0, 1.0}, {1.0, -1.0}, {-1.0, -1.0}}) {
      const Eigen::Vector3d p = pose_camera_marker * Eigen::Vector3d(0.075 * x, 0.075 * y, 0.0);
      corners_camera.emplace_back(p.x(), p.y(), p.z());
    }
    std::vector<cv::Point2d> expected;
    cv::projectPoints(corners_camera, cv::Vec3d(0, 0, 0), cv::Vec3d(0, 0, 0), k, model.distortion, expected);
    for (std::size_t c = 0; c < 4; ++c) {
      const double error = cv::norm(cv::Point2d(corners[i][c]) - expected[c]);
      EXPECT_LT(error, 0.5) << "marker " << ids[i] << " corner " << c << " at " << corners[i][c] << ", expected "
                            << expected[c];
    }
  }
  EXPECT_EQ(found, 3);
}

TEST_F(MujocoCameraTest, ABoxLandsWhereItsRaysSayToWithinAPixel) {
  const Eigen::Vector3d half(0.2, 0.15, 0.1);
  const Eigen::Isometry3d pose_camera_box = Eigen::Translation3d(0.05, 0.02, 1.5) *
                                            Eigen::AngleAxisd(0.5, Eigen::Vector3d(1, 1, 0).normalized()) *
                                            Eigen::Isometry3d::Identity();
  const Scene scene = make_scene({{camera_pose() * pose_camera_box, half, "1 1 1 1"}});
  ASSERT_TRUE(scene.model);
  const CameraModel model = camera_640();
  auto camera = make_camera(scene, model);
  RIGGER_REQUIRE_OR_SKIP(camera != nullptr, gl_error_);
  CameraFrame frame;
  ASSERT_EQ(camera->render(*scene.data, camera_pose(), {}, frame), RenderStatus::kOk);

  // Truth: the pixels whose ray crosses the box (slab test in the box frame).
  const cv::Mat rays = pixel_rays(model);
  cv::Mat truth(model.height_px, model.width_px, CV_8UC1, cv::Scalar(0));
  const Eigen::Matrix3d r_t = pose_camera_box.linear().transpose();
  const Eigen::Vector3d origin = r_t * -pose_camera_box.translation();
  for (int v = 0; v < model.height_px; ++v) {
    for (int u = 0; u < model.width_px; ++u) {
      const cv::Vec2d n = rays.at<cv::Vec2d>(v, u);
      const Eigen::Vector3d direction = r_t * Eigen::Vector3d(n[0], n[1], 1.0);
      double enter = 0.0;
      double leave = 1e9;
      for (int a = 0; a < 3; ++a) {
        const double t0 = (-half[a] - origin[a]) / direction[a];
        const double t1 = (half[a] - origin[a]) / direction[a];
        enter = std::max(enter, std::min(t0, t1));
        leave = std::min(leave, std::max(t0, t1));
      }
      truth.at<uchar>(v, u) = enter < leave ? 255 : 0;
    }
  }
  cv::Mat seen;
  cv::threshold(frame.image_mono8, seen, 30, 255, cv::THRESH_BINARY);
  cv::Mat grown;
  cv::Mat shrunk;
  cv::dilate(truth, grown, cv::Mat());
  cv::erode(truth, shrunk, cv::Mat());
  const cv::Mat outline = grown ^ shrunk;  // within a pixel of the true outline
  const cv::Mat wrong = (seen ^ truth) & ~outline;
  EXPECT_EQ(cv::countNonZero(wrong), 0);
  EXPECT_GT(cv::countNonZero(truth), 10000);
  // Depth is finite exactly where the grey image shows the box (away from its outline).
  cv::Mat finite_depth = frame.depth_m == frame.depth_m;
  EXPECT_EQ(cv::countNonZero((finite_depth ^ truth) & ~outline), 0);
}

TEST_F(MujocoCameraTest, AddsTheCameraModelsPixelNoiseToTheGreyImage) {
  const Scene scene = make_scene({{camera_pose() * Eigen::Translation3d(0, 0, 1.5), Eigen::Vector3d(0.4, 0.3, 0.1)}});
  ASSERT_TRUE(scene.model);
  auto clean = make_camera(scene, camera_640());
  RIGGER_REQUIRE_OR_SKIP(clean != nullptr, gl_error_);
  CameraModel noisy_model = camera_640();
  noisy_model.noise_stddev = 3.0;
  auto noisy = make_camera(scene, noisy_model);  // a second context on this thread
  ASSERT_NE(noisy, nullptr);
  CameraFrame a;
  CameraFrame b;
  ASSERT_EQ(clean->render(*scene.data, camera_pose(), {}, a), RenderStatus::kOk);
  ASSERT_EQ(noisy->render(*scene.data, camera_pose(), {}, b), RenderStatus::kOk);
  // Where the box is (grey far from 0 and 255, so nothing saturates): the difference is the noise.
  const auto [mean, stddev] = difference_stats(b.image_mono8, a.image_mono8);
  EXPECT_NEAR(mean, 0.0, 0.1);
  EXPECT_NEAR(stddev, 3.0, 0.15);  // and the rounding to grey levels: sqrt(9 + 1/12)
  // The depth has none.
  cv::Mat depth_a = a.depth_m.clone();
  cv::Mat depth_b = b.depth_m.clone();
  cv::patchNaNs(depth_a, -1.0);
  cv::patchNaNs(depth_b, -1.0);
  const cv::Mat same_depth = depth_a == depth_b;
  EXPECT_EQ(cv::countNonZero(same_depth), 640 * 480);
}

TEST_F(MujocoCameraTest, RepeatGivesTheLastImageWithFreshNoiseAndDepthCanBeLeftOut) {
  const Scene scene = make_scene({{camera_pose() * Eigen::Translation3d(0, 0, 1.5), Eigen::Vector3d(0.4, 0.3, 0.1)}});
  ASSERT_TRUE(scene.model);
  CameraModel noisy_model = camera_640();
  noisy_model.noise_stddev = 3.0;
  auto camera = make_camera(scene, noisy_model);
  RIGGER_REQUIRE_OR_SKIP(camera != nullptr, gl_error_);
  CameraFrame first;
  EXPECT_FALSE(camera->repeat(first));  // nothing rendered yet
  EXPECT_TRUE(first.image_mono8.empty());
  ASSERT_EQ(camera->render(*scene.data, camera_pose(), {}, first, /*depth=*/false), RenderStatus::kOk);
  EXPECT_TRUE(first.depth_m.empty());
  CameraFrame again;
  ASSERT_TRUE(camera->repeat(again));
  ASSERT_EQ(again.image_mono8.size(), first.image_mono8.size());
  // The same picture under new noise: the difference of two noise draws, sqrt(2) x 3 grey levels.
  const auto [mean, stddev] = difference_stats(again.image_mono8, first.image_mono8);
  EXPECT_NEAR(mean, 0.0, 0.1);
  EXPECT_NEAR(stddev, 3.0 * std::sqrt(2.0), 0.3);
}

TEST_F(MujocoCameraTest, RejectsANonFinitePoseAndNamesUnknownObjects) {
  const Scene scene = make_scene({{camera_pose() * Eigen::Translation3d(0, 0, 2), Eigen::Vector3d(0.1, 0.1, 0.1)}});
  ASSERT_TRUE(scene.model);
  auto camera = make_camera(scene, camera_640());
  RIGGER_REQUIRE_OR_SKIP(camera != nullptr, gl_error_);
  CameraFrame frame;
  Eigen::Isometry3d bad = camera_pose();
  bad.translation().x() = std::nan("");
  EXPECT_EQ(camera->render(*scene.data, bad, {}, frame), RenderStatus::kInvalidPose);
  EXPECT_EQ(camera->render(*scene.data, camera_pose(), {{"nobody", Eigen::Isometry3d::Identity()}}, frame),
            RenderStatus::kUnknownObject);
  EXPECT_EQ(frame.image_mono8.size(), cv::Size(640, 480));
}

}  // namespace
}  // namespace rigger::sim
