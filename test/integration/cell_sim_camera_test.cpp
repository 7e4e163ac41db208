// The cell_sim process's camera as the tracker and the tests see it (acceptance): with the default
// renderer (MuJoCo), the depth image of a known plane (the target's top face) is within a millimetre of
// the truth, the grey and depth images of a frame carry the same stamp and frame id, and the cell
// file's markers facing the camera are found in the grey image. With the rasteriser, grey images only.
// Without EGL the MuJoCo renderer stops the start (exit 2), the rasteriser runs.
#include <algorithm>
#include <cmath>
#include <iostream>
#include <fstream>
#include <map>
#include <optional>
#include <set>

#include <gtest/gtest.h>
#include <opencv2/aruco.hpp>
#include <opencv2/calib3d.hpp>

#include "cell_sim_test_support.hpp"
#include "rigger/dds/sequences.hpp"
#include "rigger/protocol/vision.hpp"
#include "rigger/sim/camera_scene.hpp"

namespace rigger::testing {
namespace {

using namespace std::chrono_literals;

struct Frame {
  std::string frame_id;
  std::string encoding;
  cv::Mat pixels;  // a copy
};

Frame to_frame(const rigger_vision_Image& im) {
  Frame f;
  f.frame_id = dds::to_string(im.header.frame_id);
  f.encoding = dds::to_string(im.encoding);
  const auto data = dds::elements(im.data);
  const int type = f.encoding == "32FC1" ? CV_32FC1 : CV_8UC1;
  if (data.size() == static_cast<std::size_t>(im.step) * im.height) {
    f.pixels = cv::Mat(static_cast<int>(im.height), static_cast<int>(im.width), type,
                       const_cast<std::uint8_t*>(data.data()), im.step)
                   .clone();
  }
  return f;
}

class CellSimCameraTest : public MultiProcessTest {
 protected:
  /// Starts cell_sim with `renderer` (on the test's domain); `env` adds to its environment.
  /// `camera_keys`: more keys of the camera section (JSON members, e.g. `"pose_error": {...}`).
  ChildProcess& launch(const std::string& renderer, const std::map<std::string, std::string>& env = {},
                       const std::string& camera_keys = "") {
    const std::string config = cell_.log_dir() + "/cell_sim.json";
    std::ofstream(config) << R"({"cell_file": ")" << repo_file("deploy/cell/simulated_cell.json")
                          << R"(", "plc": {"port": 0}, "camera": {"renderer": ")" << renderer << R"(")"
                          << (camera_keys.empty() ? "" : ", " + camera_keys) << "}}";
    return cell_.start("cell_sim", "cell_sim", {"--config", config}, true, env);
  }

  void start(const std::string& renderer, const std::string& camera_keys = "") {
    launch(renderer, {}, camera_keys);
    ASSERT_TRUE(cell_.wait_ready({"cell_sim"}, 30s));
  }

  /// The newest frame whose grey and depth images both arrived (their stamps equal), within 30 s.
  std::optional<WallTime> paired_frame() {
    // Frames of a stream may be lost (sensor stream QoS: best effort): three frames whose grey and depth
    // images both arrived, with equal stamps (a depth image stamped otherwise would never pair up).
    if (!cell_.wait_until([&] { return common_stamps().size() >= 3; }, 30s)) return std::nullopt;
    return common_stamps().back();
  }

  void subscribe() {
    image_.emplace(cell_.participant(), protocol::vision::kCameraImage);
    depth_.emplace(cell_.participant(), protocol::vision::kCameraDepth);
    cell_.loop().on_data(*image_, [this] {
      image_->take([this](const rigger_vision_Image& im, const dds_sample_info_t&) {
        images_[dds::to_domain(im.header.stamp)] = to_frame(im);
      });
    });
    cell_.loop().on_data(*depth_, [this] {
      depth_->take([this](const rigger_vision_Image& im, const dds_sample_info_t&) {
        depths_[dds::to_domain(im.header.stamp)] = to_frame(im);
      });
    });
  }

  /// The stamps both topics carried, oldest first.
  std::vector<WallTime> common_stamps() const {
    std::vector<WallTime> common;
    for (const auto& [stamp, unused] : depths_) {
      if (images_.count(stamp) != 0) common.push_back(stamp);
    }
    return common;
  }

  std::optional<dds::Reader<rigger_vision_Image>> image_;
  std::optional<dds::Reader<rigger_vision_Image>> depth_;
  std::map<WallTime, Frame> images_;
  std::map<WallTime, Frame> depths_;
};

/// How far the depth image is from the target's top face (z = 0.95 m, 0.50 x 0.40 m about (3.55, 2.25)) seen
/// from `pose_world_camera`: for every other pixel whose ray meets the face 3 cm or more inside its edges,
/// |seen - the ray's depth (z in the optical frame)|, sorted; `nan_on_face` counts such pixels without depth.
std::vector<double> target_top_errors(const cv::Mat& depth, const sim::CameraModel& c,
                                      const Eigen::Isometry3d& pose_world_camera, int& nan_on_face) {
  const Eigen::Isometry3d& pose = pose_world_camera;
  const cv::Matx33d k(c.fx_px, 0, c.cx_px, 0, c.fy_px, c.cy_px, 0, 0, 1);
  std::vector<cv::Point2f> pixels;
  for (int v = 0; v < depth.rows; v += 2) {
    for (int u = 0; u < depth.cols; u += 2) pixels.emplace_back(static_cast<float>(u), static_cast<float>(v));
  }
  std::vector<cv::Point2f> rays;
  cv::undistortPoints(pixels, rays, k, c.distortion);
  std::vector<double> errors_m;
  nan_on_face = 0;
  for (std::size_t i = 0; i < pixels.size(); ++i) {
    const Eigen::Vector3d ray_world = pose.linear() * Eigen::Vector3d(rays[i].x, rays[i].y, 1.0);
    const double s = (0.95 - pose.translation().z()) / ray_world.z();  // optical z of the hit
    if (!(s > 0.0)) continue;
    const Eigen::Vector3d hit = pose.translation() + s * ray_world;
    if (std::abs(hit.x() - 3.55) > 0.22 || std::abs(hit.y() - 2.25) > 0.17) continue;
    const float seen = depth.at<float>(static_cast<int>(pixels[i].y), static_cast<int>(pixels[i].x));
    if (std::isnan(seen)) {
      ++nan_on_face;
      continue;
    }
    errors_m.push_back(std::abs(seen - s));
  }
  std::sort(errors_m.begin(), errors_m.end());
  return errors_m;
}

int nan_count(const cv::Mat& depth) {
  int n = 0;
  for (auto it = depth.begin<float>(); it != depth.end<float>(); ++it) n += std::isnan(*it) ? 1 : 0;
  return n;
}

TEST_F(CellSimCameraTest, DepthOfTheTargetTopIsWithinAMillimetreWithTheImagesStampAndMarkersAreSeen) {
  subscribe();
  start("mujoco");
  const std::optional<WallTime> stamp = paired_frame();
  ASSERT_TRUE(stamp) << images_.size() << " images, " << depths_.size() << " depth images, none with the same stamp";
  const Frame& grey = images_.at(*stamp);
  const Frame& depth = depths_.at(*stamp);
  EXPECT_EQ(grey.frame_id, "camera");
  EXPECT_EQ(depth.frame_id, grey.frame_id);
  EXPECT_EQ(grey.encoding, "mono8");
  ASSERT_EQ(depth.encoding, "32FC1");
  ASSERT_FALSE(depth.pixels.empty());
  ASSERT_EQ(depth.pixels.size(), grey.pixels.size());

  const sim::CameraScene scene = sim::load_camera_scene(repo_file("deploy/cell/simulated_cell.json"));
  int nan_on_face = 0;
  const std::vector<double> errors_m = target_top_errors(depth.pixels, scene.camera, scene.pose_world_camera, nan_on_face);
  ASSERT_GT(errors_m.size(), 200u);
  EXPECT_EQ(nan_on_face, 0);
  const double p50 = errors_m[errors_m.size() / 2];
  const double p95 = errors_m[errors_m.size() * 95 / 100];
  std::cout << "target top: " << errors_m.size() << " pixels, depth error p50 " << p50 * 1e3 << " mm, p95 "
            << p95 * 1e3 << " mm, max " << errors_m.back() * 1e3 << " mm\n";
  EXPECT_LT(p95, 0.001);
  // The floor (an infinite plane) fills the rest of the view, nearer than the far plane: every pixel saw
  // something, so no NaN (NaN where nothing was seen is MujocoCameraTest's).
  EXPECT_EQ(nan_count(depth.pixels), 0);

  // The markers on the faces turned to the camera: the load's (1, 2) and the target's (10, 11).
  std::vector<int> ids;
  std::vector<std::vector<cv::Point2f>> corners;
  cv::aruco::detectMarkers(grey.pixels, cv::aruco::getPredefinedDictionary(scene.dictionary), corners, ids);
  const std::set<int> found(ids.begin(), ids.end());
  for (const int id : {1, 2, 10, 11}) EXPECT_EQ(found.count(id), 1u) << "marker " << id << " not found";
}

TEST_F(CellSimCameraTest, ACameraOffItsDrawingSeesFromWhereItReallyIsAndItsDepthHasHoles) {
  // 2 cm along its optical axis and 1.5 degrees about it: the images come from there, the file is unchanged.
  subscribe();
  start("mujoco", R"("pose_error": {"position_m": [0, 0, 0.02], "rpy_deg": [0, 0, 1.5]},
                      "depth_noise": {"edge_gap_m": 0.02})");
  EXPECT_NE(cell_.process("cell_sim").log().find("camera is off its cell-file pose by 20.0 mm and 1.50 deg"),
            std::string::npos);
  const std::optional<WallTime> stamp = paired_frame();
  ASSERT_TRUE(stamp) << images_.size() << " images, " << depths_.size() << " depth images";
  const cv::Mat& depth = depths_.at(*stamp).pixels;
  const sim::CameraScene scene = sim::load_camera_scene(repo_file("deploy/cell/simulated_cell.json"));
  const Eigen::Isometry3d truth =
      scene.pose_world_camera * Eigen::Translation3d(0, 0, 0.02) *
      Eigen::AngleAxisd(1.5 * 3.14159265358979323846 / 180.0, Eigen::Vector3d::UnitZ());
  int nan_from_truth = 0;
  int nan_from_file = 0;
  const std::vector<double> from_truth = target_top_errors(depth, scene.camera, truth, nan_from_truth);
  const std::vector<double> from_file = target_top_errors(depth, scene.camera, scene.pose_world_camera, nan_from_file);
  ASSERT_GT(from_truth.size(), 200u);
  ASSERT_GT(from_file.size(), 200u);
  const double truth_p95 = from_truth[from_truth.size() * 95 / 100];
  const double file_p50 = from_file[from_file.size() / 2];
  std::cout << "target top, camera 20 mm / 1.5 deg off: depth error p95 " << truth_p95 * 1e3
            << " mm from the true pose, p50 " << file_p50 * 1e3 << " mm from the file's\n";
  EXPECT_LT(truth_p95, 0.001);
  EXPECT_GT(file_p50, 0.015);
  // The depth steps (the target's and the load's outlines against the floor) are holes now.
  EXPECT_GT(nan_count(depth), 500);
}

TEST_F(CellSimCameraTest, TheRasteriserPublishesGreyImagesAndNoDepth) {
  subscribe();
  start("raster");
  ASSERT_TRUE(cell_.wait_until([&] { return images_.size() >= 3; }, 30s));
  // cell_sim's endpoints are discovered together (one participant): its image writer matched, so a depth
  // writer would have too.
  EXPECT_EQ(image_->matched_writers(), 1u);
  EXPECT_EQ(depth_->matched_writers(), 0u);
  EXPECT_TRUE(depths_.empty());
  EXPECT_EQ(images_.rbegin()->second.encoding, "mono8");
}

// glvnd finds no EGL vendor library: no EGL display, as on a host without Mesa's EGL.
const std::map<std::string, std::string> kNoEgl{{"__EGL_VENDOR_LIBRARY_FILENAMES", "/nonexistent/egl_vendor.json"}};

TEST_F(CellSimCameraTest, WithoutEglTheMujocoRendererStopsTheStartWithExitCode2) {
  ChildProcess& refused = launch("mujoco", kNoEgl);
  const auto status = refused.wait(30s);
  ASSERT_TRUE(status.has_value()) << "cell_sim kept running without a renderer";
  EXPECT_EQ(status->code, 2);
  EXPECT_NE(refused.log().find("/camera"), std::string::npos) << refused.log();
  EXPECT_NE(refused.log().find("raster"), std::string::npos) << refused.log();
  expect_clean_exit_ = false;
}

TEST_F(CellSimCameraTest, WithoutEglTheRasteriserStillRuns) {
  subscribe();
  launch("raster", kNoEgl);
  ASSERT_TRUE(cell_.wait_ready({"cell_sim"}, 30s));
  EXPECT_TRUE(cell_.wait_until([&] { return images_.size() >= 3; }, 30s));
}

}  // namespace
}  // namespace rigger::testing
