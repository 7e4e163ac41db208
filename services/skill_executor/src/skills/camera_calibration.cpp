#include "camera_calibration.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <stdexcept>

#include <Eigen/Dense>

namespace rigger::skill_executor::calibration {

Eigen::Vector2d project_through_lens(const cell::CameraIntrinsics& camera, const Eigen::Vector3d& p) {
  const std::vector<double>& d = camera.distortion;
  const auto k = [&d](std::size_t i) { return i < d.size() ? d[i] : 0.0; };
  const double x = p.x() / p.z(), y = p.y() / p.z();
  const double r2 = x * x + y * y, r4 = r2 * r2, r6 = r4 * r2;
  const double radial = (1.0 + k(0) * r2 + k(1) * r4 + k(4) * r6) / (1.0 + k(5) * r2 + k(6) * r4 + k(7) * r6);
  const double xd = x * radial + 2.0 * k(2) * x * y + k(3) * (r2 + 2.0 * x * x) + k(8) * r2 + k(9) * r4;
  const double yd = y * radial + k(2) * (r2 + 2.0 * y * y) + 2.0 * k(3) * x * y + k(10) * r2 + k(11) * r4;
  return {camera.fx_px * xd + camera.cx_px, camera.fy_px * yd + camera.cy_px};
}

namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kGoldenAngle = 2.39996322972865332;  // rad: successive axes never repeat
constexpr double kImageMargin = 0.05;                 // of the image's width and height
constexpr double kMaxViewAngle = 60.0 * kPi / 180.0;  // between the board's normal and the line of sight
constexpr double kMinPairAngle = 2.0 * kPi / 180.0;
constexpr int kMaxIterations = 30;

// The board's four corners and its centre, in its frame.
std::array<Eigen::Vector3d, 5> board_points(double size_m) {
  const double h = size_m / 2.0;
  return {Eigen::Vector3d(-h, -h, 0), Eigen::Vector3d(h, -h, 0), Eigen::Vector3d(h, h, 0), Eigen::Vector3d(-h, h, 0),
          Eigen::Vector3d::Zero()};
}

// How far (px) the picture of a square of half size `half_m` about the board's centre, in its plane, must move
// to lie within the picture's margin: (0, 0) when it does. A square larger than the picture is centred on it.
Eigen::Vector2d shift_into_picture(const Eigen::Isometry3d& camera_board, const cell::CameraIntrinsics& camera,
                                   double half_m) {
  Eigen::Vector2d low = Eigen::Vector2d::Constant(std::numeric_limits<double>::max());
  Eigen::Vector2d high = Eigen::Vector2d::Constant(std::numeric_limits<double>::lowest());
  for (const double x : {-half_m, half_m}) {
    for (const double y : {-half_m, half_m}) {
      const Eigen::Vector2d px = project_through_lens(camera, camera_board * Eigen::Vector3d(x, y, 0.0));
      low = low.cwiseMin(px);
      high = high.cwiseMax(px);
    }
  }
  const Eigen::Vector2d size(camera.width_px, camera.height_px);
  const Eigen::Vector2d margin = kImageMargin * size;
  Eigen::Vector2d shift = Eigen::Vector2d::Zero();
  for (int i = 0; i < 2; ++i) {
    if (high(i) - low(i) > size(i) - 2.0 * margin(i))
      shift(i) = 0.5 * size(i) - 0.5 * (low(i) + high(i));
    else if (low(i) < margin(i))
      shift(i) = margin(i) - low(i);
    else if (high(i) > size(i) - margin(i))
      shift(i) = size(i) - margin(i) - high(i);
  }
  return shift;
}

bool in_view(const Eigen::Isometry3d& camera_board, const cell::CameraIntrinsics& camera, double size_m) {
  const Eigen::Vector3d to_camera = -camera_board.translation().normalized();
  if (std::acos(std::clamp(camera_board.linear().col(2).dot(to_camera), -1.0, 1.0)) > kMaxViewAngle) return false;
  for (const Eigen::Vector3d& corner : board_points(size_m))
    if ((camera_board * corner).z() <= 0.0) return false;
  // The whole board in the picture, through the lens: a board cut by the picture's edge loses the markers
  // that measure its tilt best.
  return shift_into_picture(camera_board, camera, size_m / 2.0).isZero();
}

// A small change of a pose: rotation vector (rad) and translation (m), applied on the right.
Eigen::Isometry3d perturbed(const Eigen::Isometry3d& pose, const Eigen::Matrix<double, 6, 1>& d) {
  Eigen::Isometry3d step = Eigen::Isometry3d::Identity();
  const double angle = d.head<3>().norm();
  if (angle > 0.0) step.linear() = Eigen::AngleAxisd(angle, d.head<3>() / angle).toRotationMatrix();
  step.translation() = d.tail<3>();
  Eigen::Isometry3d out = pose * step;
  // Keep the rotation orthonormal through the iterations.
  out.linear() = Eigen::Quaterniond(out.linear()).normalized().toRotationMatrix();
  return out;
}

// The residual of every board point of every pair (m): where X B Y puts it minus where the camera saw it.
Eigen::VectorXd residuals(const std::vector<PosePair>& pairs, const Eigen::Isometry3d& camera_base,
                          const Eigen::Isometry3d& tool_board, const std::array<Eigen::Vector3d, 5>& points) {
  Eigen::VectorXd r(static_cast<Eigen::Index>(pairs.size() * points.size() * 3));
  Eigen::Index row = 0;
  for (const PosePair& pair : pairs) {
    const Eigen::Isometry3d predicted = camera_base * pair.pose_base_tool * tool_board;
    for (const Eigen::Vector3d& p : points) {
      r.segment<3>(row) = predicted * p - pair.pose_camera_board * p;
      row += 3;
    }
  }
  return r;
}

}  // namespace

double angle_deg(const Eigen::Matrix3d& rotation) {
  return Eigen::AngleAxisd(rotation).angle() * 180.0 / kPi;
}

nlohmann::json pose_json(const Eigen::Isometry3d& pose) {
  // eulerAngles(2, 1, 0) gives (yaw, pitch, roll) for R = Rz(yaw) Ry(pitch) Rx(roll), the cell file's order.
  const Eigen::Vector3d ypr = pose.linear().eulerAngles(2, 1, 0) * 180.0 / kPi;
  const Eigen::Vector3d& p = pose.translation();
  return {{"position_m", {p.x(), p.y(), p.z()}}, {"rpy_deg", {ypr.z(), ypr.y(), ypr.x()}}};
}

std::vector<Eigen::Isometry3d> plan_poses(const PosePlanInput& in) {
  const Eigen::Isometry3d base_board_now = in.pose_base_tool_now * in.pose_tool_board;
  const Eigen::Isometry3d camera_base = in.pose_base_camera.inverse();
  const Eigen::Isometry3d board_tool = in.pose_tool_board.inverse();
  // The smallest turn that makes the board at `centre` face the camera, from how the arm holds it now.
  const auto facing_at = [&](const Eigen::Vector3d& centre) {
    const Eigen::Vector3d to_camera = (in.pose_base_camera.translation() - centre).normalized();
    Eigen::Isometry3d base_board = Eigen::Isometry3d::Identity();
    base_board.linear() =
        Eigen::Quaterniond::FromTwoVectors(base_board_now.linear().col(2), to_camera).toRotationMatrix() *
        base_board_now.linear();
    base_board.translation() = centre;
    return base_board;
  };
  // The centre moved across the line of sight (by at most max_recentre_m) until the facing board, grown by
  // shift_m on every side, is in the picture: the poses about it then keep the whole board in view.
  Eigen::Isometry3d facing = facing_at(base_board_now.translation());
  for (int i = 0; i < 8; ++i) {
    const Eigen::Isometry3d camera_board = camera_base * facing;
    const Eigen::Vector2d px = shift_into_picture(camera_board, in.camera, in.board_size_m / 2.0 + in.shift_m);
    if (px.norm() < 0.5) break;
    const double depth = camera_board.translation().z();
    const Eigen::Vector3d step_camera(px.x() * depth / in.camera.fx_px, px.y() * depth / in.camera.fy_px, 0.0);
    Eigen::Vector3d moved = facing.translation() + in.pose_base_camera.linear() * step_camera -
                            base_board_now.translation();
    if (moved.norm() > in.max_recentre_m) moved *= in.max_recentre_m / moved.norm();
    facing = facing_at(base_board_now.translation() + moved);
  }
  std::vector<Eigen::Isometry3d> poses;
  for (int k = 0; k < 4 * in.count && static_cast<int>(poses.size()) < in.count; ++k) {
    Eigen::Isometry3d base_board = facing;
    if (k > 0) {
      const double phi = k * kGoldenAngle;
      const Eigen::Vector3d axis(std::cos(phi), std::sin(phi), 0.0);
      const double spin = (k % 2 == 0 ? 0.5 : -0.5) * in.tilt_rad;
      base_board.linear() = facing.linear() * Eigen::AngleAxisd(in.tilt_rad, axis).toRotationMatrix() *
                            Eigen::AngleAxisd(spin, Eigen::Vector3d::UnitZ()).toRotationMatrix();
      base_board.translation() +=
          facing.linear() * (in.shift_m * Eigen::Vector3d(-std::sin(phi), std::cos(phi), 0.0));
    }
    if (!in_view(camera_base * base_board, in.camera, in.board_size_m)) continue;
    poses.push_back(base_board * board_tool);
  }
  return poses;
}

double axis_spread_deg(const std::vector<Eigen::Isometry3d>& poses_base_tool) {
  Eigen::Matrix3d scatter = Eigen::Matrix3d::Zero();
  int axes = 0;
  for (std::size_t i = 0; i < poses_base_tool.size(); ++i) {
    for (std::size_t j = i + 1; j < poses_base_tool.size(); ++j) {
      const Eigen::AngleAxisd relative(poses_base_tool[i].linear().transpose() * poses_base_tool[j].linear());
      if (relative.angle() < kMinPairAngle) continue;
      scatter += relative.axis() * relative.axis().transpose();  // the axis' sign does not count
      ++axes;
    }
  }
  if (axes < 2) return 0.0;
  const Eigen::Vector3d eigen = Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(scatter).eigenvalues();  // ascending
  return std::atan2(std::sqrt(std::max(eigen(1), 0.0)), std::sqrt(std::max(eigen(2), 0.0))) * 180.0 / kPi;
}

Solution solve(const std::vector<PosePair>& pairs, const Eigen::Isometry3d& mount_guess, double board_size_m) {
  if (pairs.size() < 3) throw std::invalid_argument("a camera pose needs at least 3 pose pairs");
  const auto points = board_points(board_size_m);
  Eigen::Isometry3d tool_board = mount_guess;
  // The first pair, with the guessed mount, places the camera to start from.
  Eigen::Isometry3d camera_base = pairs[0].pose_camera_board * tool_board.inverse() * pairs[0].pose_base_tool.inverse();
  Solution s;
  Eigen::VectorXd r = residuals(pairs, camera_base, tool_board, points);
  for (s.iterations = 0; s.iterations < kMaxIterations; ++s.iterations) {
    // Central differences: 12 unknowns, a few hundred residuals.
    Eigen::MatrixXd jacobian(r.size(), 12);
    constexpr double kStep = 1e-6;
    for (int c = 0; c < 12; ++c) {
      Eigen::Matrix<double, 6, 1> d = Eigen::Matrix<double, 6, 1>::Zero();
      d(c % 6) = kStep;
      const bool camera = c < 6;
      const Eigen::VectorXd plus = residuals(pairs, camera ? perturbed(camera_base, d) : camera_base,
                                             camera ? tool_board : perturbed(tool_board, d), points);
      const Eigen::VectorXd minus = residuals(pairs, camera ? perturbed(camera_base, -d) : camera_base,
                                              camera ? tool_board : perturbed(tool_board, -d), points);
      jacobian.col(c) = (plus - minus) / (2.0 * kStep);
    }
    Eigen::MatrixXd normal = jacobian.transpose() * jacobian;
    normal.diagonal() *= 1.0 + 1e-9;  // a whisker of damping against a flat direction
    const Eigen::VectorXd step = normal.ldlt().solve(-jacobian.transpose() * r);
    if (!step.allFinite()) break;
    const Eigen::Isometry3d next_camera = perturbed(camera_base, step.head<6>());
    const Eigen::Isometry3d next_mount = perturbed(tool_board, step.tail<6>());
    const Eigen::VectorXd next_r = residuals(pairs, next_camera, next_mount, points);
    if (next_r.squaredNorm() > r.squaredNorm()) break;
    camera_base = next_camera;
    tool_board = next_mount;
    r = next_r;
    if (step.norm() < 1e-10) break;
  }
  s.pose_base_camera = camera_base.inverse();
  s.pose_tool_board = tool_board;
  double sum_mm = 0.0, sum_deg = 0.0;
  for (const PosePair& pair : pairs) {
    const Eigen::Isometry3d predicted = camera_base * pair.pose_base_tool * tool_board;
    PoseResidual e;
    e.mm = (predicted.translation() - pair.pose_camera_board.translation()).norm() * 1e3;
    e.deg = angle_deg(predicted.linear().transpose() * pair.pose_camera_board.linear());
    sum_mm += e.mm * e.mm;
    sum_deg += e.deg * e.deg;
    s.max_mm = std::max(s.max_mm, e.mm);
    s.max_deg = std::max(s.max_deg, e.deg);
    s.residuals.push_back(e);
  }
  s.rms_mm = std::sqrt(sum_mm / static_cast<double>(pairs.size()));
  s.rms_deg = std::sqrt(sum_deg / static_cast<double>(pairs.size()));
  return s;
}

}  // namespace rigger::skill_executor::calibration
