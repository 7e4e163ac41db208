// Markerless localization against depth images rendered by the simulator's MuJoCo camera with its
// depth noise: the demo load (a 0.40 x 0.30 x 0.20 m box) and an L-bracket made here, at 50 random
// poses on a table each. Real rendering (EGL, llvmpipe on a machine without a GPU).
#include "rigger/perception/localize.hpp"

#include <gtest/gtest.h>
#include <opencv2/aruco.hpp>

#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <memory>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "rigger/cad/model.hpp"
#include "rigger/cad/tessellation.hpp"
#include "rigger/sim/mujoco_camera.hpp"
#include "rigger/testing/require.hpp"

namespace rigger::perception {
namespace {

struct ModelDeleter {
  void operator()(mjModel* m) const { mj_deleteModel(m); }
};
struct DataDeleter {
  void operator()(mjData* d) const { mj_deleteData(d); }
};

/// A box of the part, in the part's frame.
struct PartBox {
  Eigen::Vector3d centre_m;
  Eigen::Vector3d half_m;
};

constexpr double kTableTopM = 0.75;

/// The part as boxes, the mesh localize() gets (their triangles, outward winding).
Mesh mesh_of(const std::vector<PartBox>& boxes) {
  Mesh mesh;
  // Faces of the unit cube as corner indices (bit 0: x, bit 1: y, bit 2: z), clockwise seen from
  // outside: localize() takes either winding of a closed surface.
  const int faces[6][4] = {{0, 2, 6, 4}, {1, 5, 7, 3}, {0, 4, 5, 1}, {2, 3, 7, 6}, {0, 1, 3, 2}, {4, 6, 7, 5}};
  for (const PartBox& box : boxes) {
    const int base = static_cast<int>(mesh.vertices_m.size());
    for (int corner = 0; corner < 8; ++corner) {
      const Eigen::Vector3d sign((corner & 1) ? 1 : -1, (corner & 2) ? 1 : -1, (corner & 4) ? 1 : -1);
      mesh.vertices_m.push_back(box.centre_m + sign.cwiseProduct(box.half_m));
    }
    for (const auto& f : faces) {
      mesh.triangles.emplace_back(base + f[0], base + f[1], base + f[2]);
      mesh.triangles.emplace_back(base + f[0], base + f[2], base + f[3]);
    }
  }
  return mesh;
}

/// A table and the part on a free joint, so that one compiled model serves every pose.
struct Cell {
  std::unique_ptr<mjModel, ModelDeleter> model;
  std::unique_ptr<mjData, DataDeleter> data;

  void place(const Eigen::Isometry3d& pose_world_part) {
    const Eigen::Quaterniond q(pose_world_part.linear());
    for (int i = 0; i < 3; ++i) {
      data->qpos[i] = pose_world_part.translation()[i];
    }
    data->qpos[3] = q.w();
    data->qpos[4] = q.x();
    data->qpos[5] = q.y();
    data->qpos[6] = q.z();
    mj_forward(model.get(), data.get());
  }
};

Cell make_cell(const std::vector<PartBox>& boxes) {
  std::ostringstream xml;
  xml.precision(17);
  xml << "<mujoco><visual><headlight ambient='0.35 0.35 0.35' diffuse='0.55 0.55 0.55' specular='0 0 0'/>"
         "</visual><option gravity='0 0 0'/><worldbody>"
      << "<geom type='box' pos='0 0 " << kTableTopM - 0.02 << "' size='0.8 0.6 0.02' rgba='0.5 0.5 0.5 1'/>"
      << "<body name='part'><freejoint/>";
  for (const PartBox& box : boxes) {
    xml << "<geom type='box' pos='" << box.centre_m.x() << ' ' << box.centre_m.y() << ' ' << box.centre_m.z()
        << "' size='" << box.half_m.x() << ' ' << box.half_m.y() << ' ' << box.half_m.z() << "' rgba='0.8 0.8 0.8 1'/>";
  }
  xml << "</body></worldbody></mujoco>";
  const std::filesystem::path path =
      std::filesystem::temp_directory_path() / ("rigger_perception_test_" + std::to_string(::getpid()) + ".xml");
  std::ofstream(path) << xml.str();
  char error[1000] = "";
  Cell cell;
  cell.model.reset(mj_loadXML(path.c_str(), nullptr, error, sizeof error));
  std::filesystem::remove(path);
  if (!cell.model) {
    ADD_FAILURE() << "MJCF: " << error;
    return cell;
  }
  cell.data.reset(mj_makeData(cell.model.get()));
  return cell;
}

/// The demo cell's camera intrinsics, 1.6 m from the table's centre, looking down at about 50 degrees.
sim::CameraModel demo_camera() {
  return sim::CameraModel::pinhole(1280, 720, 1000.0, 640.0, 360.0);
}

Eigen::Isometry3d camera_pose() {
  const Eigen::Vector3d eye(0.0, -1.0, kTableTopM + 1.2);
  const Eigen::Vector3d target(0.0, 0.0, kTableTopM);
  const Eigen::Vector3d z = (target - eye).normalized();
  const Eigen::Vector3d y = -(Eigen::Vector3d::UnitZ() - Eigen::Vector3d::UnitZ().dot(z) * z).normalized();
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  pose.linear().col(0) = y.cross(z);
  pose.linear().col(1) = y;
  pose.linear().col(2) = z;
  pose.translation() = eye;
  return pose;
}

DepthFrame frame_of(const cv::Mat& depth_m) {
  const sim::CameraModel c = demo_camera();
  return {depth_m, {c.fx_px, c.fy_px, c.cx_px, c.cy_px}, camera_pose()};
}

LocalizeOptions table_options() {
  LocalizeOptions options;
  // Above the table by five times its depth noise there (about 2.4 mm at 1.6 m).
  options.min_height_world_m = kTableTopM + 0.012;
  return options;
}

sim::MujocoCameraSettings noisy() {
  sim::MujocoCameraSettings settings;
  settings.depth_noise.stddev_at_1m_m = 0.001;
  settings.depth_noise.grazing_deg = 80.0;
  settings.depth_noise.edge_gap_m = 0.01;
  return settings;
}

/// Position and rotation error to the nearest symmetric equivalent of the truth.
std::pair<double, double> errors(const Localizer& localizer, const Eigen::Isometry3d& found,
                                 const Eigen::Isometry3d& truth, const Eigen::Vector3d& centre_object_m) {
  double best_mm = 1e9;
  double best_deg = 1e9;
  for (const Eigen::Matrix3d& s : localizer.symmetries()) {
    // The symmetry turns about the part's centre; compare the centres and the orientations.
    const Eigen::Matrix3d r = truth.linear() * s;
    const double deg = Eigen::AngleAxisd(r.transpose() * found.linear()).angle() * 180.0 / M_PI;
    if (deg < best_deg) {
      best_deg = deg;
    }
  }
  best_mm = ((found * centre_object_m) - (truth * centre_object_m)).norm() * 1000.0;
  return {best_mm, best_deg};
}

double percentile(std::vector<double> values, double fraction) {
  if (values.empty()) {
    return std::nan("");
  }
  std::sort(values.begin(), values.end());
  return values[static_cast<std::size_t>(std::ceil(fraction * values.size())) - 1];
}

const std::vector<PartBox> kLoad = {{Eigen::Vector3d::Zero(), Eigen::Vector3d(0.20, 0.15, 0.10)}};
// A bracket: a 200 x 120 x 20 mm plate with a 20 mm upright 100 mm tall along one short edge;
// frame at the plate's bottom centre.
const std::vector<PartBox> kBracket = {{Eigen::Vector3d(0.0, 0.0, 0.01), Eigen::Vector3d(0.10, 0.06, 0.01)},
                                       {Eigen::Vector3d(-0.09, 0.0, 0.07), Eigen::Vector3d(0.01, 0.06, 0.05)}};

class MarkerlessLocalizeTest : public ::testing::Test {
 protected:
  std::unique_ptr<sim::MujocoCamera> make_camera(const Cell& cell) {
    try {
      return std::make_unique<sim::MujocoCamera>(*cell.model, demo_camera(), std::vector<sim::BoxObject>{},
                                                 cv::aruco::DICT_4X4_50, noisy());
    } catch (const sim::GlUnavailableError& e) {
      gl_error_ = e.what();
      return nullptr;
    }
  }

  /// 50 poses resting on the table (random place and yaw), localized without a prior. Prints the
  /// table; fails on any pose reported found more than 10 mm or 2 degrees off, and when fewer than
  /// `min_found` are found.
  void check_accuracy(const char* name, const std::vector<PartBox>& boxes, double rest_height_m,
                      const Eigen::Vector3d& centre_m, int min_found) {
    Cell cell = make_cell(boxes);
    ASSERT_TRUE(cell.model);
    auto camera = make_camera(cell);
    RIGGER_REQUIRE_OR_SKIP(camera != nullptr, gl_error_);
    Localizer localizer(mesh_of(boxes), table_options());
    std::mt19937_64 random(7);
    std::uniform_real_distribution<double> x(-0.3, 0.3);
    std::uniform_real_distribution<double> y(-0.2, 0.2);
    std::uniform_real_distribution<double> yaw(-M_PI, M_PI);
    std::vector<double> position_mm;
    std::vector<double> rotation_deg;
    std::vector<double> elapsed_ms;
    int wrong = 0;
    std::map<std::string, int> failures;
    for (int i = 0; i < 50; ++i) {
      const Eigen::Isometry3d truth = Eigen::Translation3d(x(random), y(random), kTableTopM + rest_height_m) *
                                      Eigen::AngleAxisd(yaw(random), Eigen::Vector3d::UnitZ()) *
                                      Eigen::Isometry3d::Identity();
      cell.place(truth);
      sim::CameraFrame frame;
      ASSERT_EQ(camera->render(*cell.data, camera_pose(), {}, frame), sim::RenderStatus::kOk);
      const LocalizeResult result = localizer.localize(frame_of(frame.depth_m));
      elapsed_ms.push_back(result.elapsed.count() / 1000.0);
      if (result.status != LocalizeStatus::kFound) {
        ++failures[to_string(result.status)];
        continue;
      }
      const auto [mm, deg] = errors(localizer, result.pose_world_object, truth, centre_m);
      if (mm > 10.0 || deg > 2.0) {
        ++wrong;
        ADD_FAILURE() << "pose " << i << " found " << mm << " mm, " << deg << " deg off; rms " << result.rms_m
                      << " inlier ratio " << result.inlier_ratio << " model support " << result.model_support;
      }
      position_mm.push_back(mm);
      rotation_deg.push_back(deg);
    }
    std::printf(
        "%-12s found %2zu/50 wrong %d | position p50 %.2f p95 %.2f mm | rotation p50 %.2f p95 %.2f deg | "
        "time p50 %.0f p99 %.0f ms |",
        name, position_mm.size(), wrong, percentile(position_mm, 0.5), percentile(position_mm, 0.95),
        percentile(rotation_deg, 0.5), percentile(rotation_deg, 0.95), percentile(elapsed_ms, 0.5),
        percentile(elapsed_ms, 0.99));
    for (const auto& [status, count] : failures) {
      std::printf(" %s %d", status.c_str(), count);
    }
    std::printf("\n");
    EXPECT_EQ(wrong, 0);
    EXPECT_GE(static_cast<int>(position_mm.size()), min_found);
    RecordProperty("position_p95_mm", std::to_string(percentile(position_mm, 0.95)));
    RecordProperty("rotation_p95_deg", std::to_string(percentile(rotation_deg, 0.95)));
  }

  /// The depth image of the demo load at `truth` on the table; empty (gl_error_ set) without OpenGL.
  cv::Mat load_depth(const Eigen::Isometry3d& truth) {
    Cell cell = make_cell(kLoad);
    auto camera = cell.model ? make_camera(cell) : nullptr;
    if (camera == nullptr) {
      return {};
    }
    cell.place(truth);
    sim::CameraFrame frame;
    if (camera->render(*cell.data, camera_pose(), {}, frame) != sim::RenderStatus::kOk) {
      ADD_FAILURE() << "rendering failed";
    }
    return frame.depth_m;
  }

  std::string gl_error_;
};

TEST_F(MarkerlessLocalizeTest, ReportsNoWrongPoseOfTheDemoLoadAtFiftyPoses) {
  check_accuracy("demo load", kLoad, 0.10, Eigen::Vector3d::Zero(), 45);
}

TEST_F(MarkerlessLocalizeTest, ReportsNoWrongPoseOfAnLBracketAtFiftyPoses) {
  check_accuracy("L-bracket", kBracket, 0.0, Eigen::Vector3d(-0.02, 0.0, 0.03), 20);
}

TEST_F(MarkerlessLocalizeTest, FindsTheLoadsThreeHalfTurnsAndNoneOfTheBracket) {
  const Localizer load(mesh_of(kLoad));
  EXPECT_EQ(load.symmetries().size(), 4U);
  const Localizer bracket(mesh_of(kBracket));
  EXPECT_EQ(bracket.symmetries().size(), 1U);  // its mirror image is not a turn
}

TEST_F(MarkerlessLocalizeTest, FindsTheThreeHalfTurnsOfTheDemoLoadsStepModel) {
  // The shipped model (four through holes), as the CAD service tessellates it: near its edges a turned
  // point may have only the next face's samples near it, a few millimetres off; still a symmetry.
  const cad::TriangleMesh triangles =
      cad::triangle_mesh(cad::read_step_file(std::string(RIGGER_SOURCE_DIR) + "/deploy/cell/models/load.step"));
  const Localizer load(Mesh{triangles.vertices_m, triangles.triangles});
  EXPECT_EQ(load.symmetries().size(), 4U);
  const LocalizeResult none = Localizer(Mesh{triangles.vertices_m, triangles.triangles}).localize(frame_of(cv::Mat()));
  EXPECT_EQ(none.symmetry, "2-fold about x, 2-fold about y, 2-fold about z");
}

TEST_F(MarkerlessLocalizeTest, ABumpOnOneEndLeavesOnlyTheTurnThatMapsIt) {
  // A 20 x 20 x 10 mm bump on the load's +x face, on its x axis: a fraction of a per cent of the surface,
  // but 10 mm off any face when turned about y or z; the half turn about x maps it onto itself.
  const Localizer bumped(mesh_of({kLoad.front(), {Eigen::Vector3d(0.205, 0.0, 0.0), Eigen::Vector3d(0.005, 0.01, 0.01)}}));
  ASSERT_EQ(bumped.symmetries().size(), 2U);
  EXPECT_TRUE(bumped.symmetries()[1].isApprox(Eigen::AngleAxisd(M_PI, Eigen::Vector3d::UnitX()).toRotationMatrix()));
}

TEST_F(MarkerlessLocalizeTest, AllNanOrEmptyDepthIsBadDepth) {
  Localizer localizer(mesh_of(kLoad), table_options());
  const cv::Mat nan(720, 1280, CV_32FC1, cv::Scalar(std::nan("")));
  EXPECT_EQ(localizer.localize(frame_of(nan)).status, LocalizeStatus::kBadDepth);
  EXPECT_EQ(localizer.localize(frame_of(cv::Mat())).status, LocalizeStatus::kBadDepth);
  const cv::Mat wrong_type(720, 1280, CV_16UC1, cv::Scalar(1000));
  EXPECT_EQ(localizer.localize(frame_of(wrong_type)).status, LocalizeStatus::kBadDepth);
}

TEST_F(MarkerlessLocalizeTest, APartOutOfViewIsAFailureCodeNeverAPose) {
  Cell cell = make_cell(kLoad);
  ASSERT_TRUE(cell.model);
  auto camera = make_camera(cell);
  RIGGER_REQUIRE_OR_SKIP(camera != nullptr, gl_error_);
  cell.place(Eigen::Translation3d(5.0, 5.0, kTableTopM + 0.1) * Eigen::Isometry3d::Identity());
  sim::CameraFrame frame;
  ASSERT_EQ(camera->render(*cell.data, camera_pose(), {}, frame), sim::RenderStatus::kOk);
  // The table alone: nothing above it.
  Localizer above_table(mesh_of(kLoad), table_options());
  EXPECT_EQ(above_table.localize(frame_of(frame.depth_m)).status, LocalizeStatus::kNoVisibleSurface);
  // Without the table dropped, the flat table must not pass for the box.
  Localizer anywhere(mesh_of(kLoad));
  const LocalizeResult result = anywhere.localize(frame_of(frame.depth_m));
  EXPECT_NE(result.status, LocalizeStatus::kFound) << result.message;
}

TEST_F(MarkerlessLocalizeTest, RefinesFromAPriorAndReportsTheEquivalentNearestIt) {
  const Eigen::Isometry3d truth = Eigen::Translation3d(0.1, 0.05, kTableTopM + 0.1) *
                                  Eigen::AngleAxisd(0.4, Eigen::Vector3d::UnitZ()) * Eigen::Isometry3d::Identity();
  sim::CameraFrame frame;
  frame.depth_m = load_depth(truth);
  RIGGER_REQUIRE_OR_SKIP(!frame.depth_m.empty(), gl_error_);
  Localizer localizer(mesh_of(kLoad), table_options());
  // The prior is 2 cm and 4 degrees off, and turned half a turn (a symmetric equivalent).
  const Eigen::Isometry3d prior =
      Eigen::Translation3d(0.02, -0.01, 0.0) * truth * Eigen::AngleAxisd(M_PI + 0.07, Eigen::Vector3d::UnitZ());
  const LocalizeResult result = localizer.localize(frame_of(frame.depth_m), prior);
  ASSERT_EQ(result.status, LocalizeStatus::kFound) << result.message;
  EXPECT_LT((result.pose_world_object.translation() - truth.translation()).norm(), 0.003);
  // The equivalent nearest the prior: truth turned half a turn about z.
  const Eigen::Matrix3d expected =
      truth.linear() * Eigen::AngleAxisd(M_PI, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  EXPECT_LT(Eigen::AngleAxisd(expected.transpose() * result.pose_world_object.linear()).angle() * 180.0 / M_PI, 0.5);
  EXPECT_NE(result.symmetry.find("2-fold about z"), std::string::npos) << result.symmetry;
  EXPECT_LT(result.rms_m, 0.0025);
  EXPECT_GT(result.inlier_ratio, 0.7);
}

TEST_F(MarkerlessLocalizeTest, AFitFromAPriorIsJudgedInThePartsBoxAndTrackingNeverSearches) {
  // The load on the table with the table kept (no support height): one connected surface, table and load,
  // wider than the part, which the search from no prior refuses to take for it. From a prior the fit is
  // judged on what lies in the load's box: found. Tracking from a prior far off refuses, and does not
  // search the image instead.
  const Eigen::Isometry3d truth = Eigen::Translation3d(0.05, 0.0, kTableTopM + 0.1) *
                                  Eigen::AngleAxisd(0.3, Eigen::Vector3d::UnitZ()) * Eigen::Isometry3d::Identity();
  sim::CameraFrame frame;
  frame.depth_m = load_depth(truth);
  RIGGER_REQUIRE_OR_SKIP(!frame.depth_m.empty(), gl_error_);
  const Eigen::Isometry3d prior = Eigen::Translation3d(0.015, -0.01, 0.005) * truth *
                                  Eigen::AngleAxisd(0.05, Eigen::Vector3d::UnitZ());
  Localizer once{mesh_of(kLoad)};
  EXPECT_NE(once.localize(frame_of(frame.depth_m)).status, LocalizeStatus::kFound);
  const LocalizeResult found = once.localize(frame_of(frame.depth_m), prior);
  ASSERT_EQ(found.status, LocalizeStatus::kFound) << found.message;
  const auto [mm, deg] = errors(once, found.pose_world_object, truth, Eigen::Vector3d::Zero());
  EXPECT_LT(mm, 5.0);  // the table under it pulls at its bottom edge: within the insertion's 5 mm
  EXPECT_LT(deg, 0.5);
  LocalizeOptions tracking;
  tracking.search_when_prior_fails = false;
  Localizer tracker(mesh_of(kLoad), tracking);
  const Eigen::Isometry3d far = Eigen::Translation3d(0.3, 0.0, 0.0) * truth;
  const LocalizeResult lost = tracker.localize(frame_of(frame.depth_m), far);
  EXPECT_NE(lost.status, LocalizeStatus::kFound) << "tracking does not search the image for a part it lost";
}

}  // namespace
}  // namespace rigger::perception
