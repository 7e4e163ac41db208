#include "hand_eye.hpp"

#include <opencv2/calib3d.hpp>
#include <opencv2/core/eigen.hpp>

#include <Eigen/Eigenvalues>

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace rigger::vision {
namespace {

constexpr double kDeg = M_PI / 180.0;
constexpr double kMinPairAngleRad = 5.0 * kDeg;

double rotation_angle(const Eigen::Matrix3d& r) { return Eigen::AngleAxisd(r).angle(); }

/// A small motion (dx, dy, dz, rx, ry, rz) as a transform: rotation vector then translation.
Eigen::Isometry3d exp_motion(const Eigen::Matrix<double, 6, 1>& d) {
  Eigen::Isometry3d t = Eigen::Isometry3d::Identity();
  const Eigen::Vector3d w = d.tail<3>();
  if (w.norm() > 0.0) t.linear() = Eigen::AngleAxisd(w.norm(), w.normalized()).toRotationMatrix();
  t.translation() = d.head<3>();
  return t;
}

/// The board's mount that best fits every sample for a given camera pose: the mean of the samples'
/// own (translation mean, rotation by the principal eigenvector of the quaternions' outer products).
Eigen::Isometry3d mean_mount(const std::vector<HandEyeSample>& samples, const Eigen::Isometry3d& base_camera) {
  Eigen::Vector3d t = Eigen::Vector3d::Zero();
  Eigen::Matrix4d q_sum = Eigen::Matrix4d::Zero();
  for (const HandEyeSample& s : samples) {
    const Eigen::Isometry3d tool_board = s.pose_base_tool.inverse() * base_camera * s.pose_camera_board;
    t += tool_board.translation();
    const Eigen::Quaterniond q(tool_board.linear());
    const Eigen::Vector4d v(q.w(), q.x(), q.y(), q.z());
    q_sum += v * v.transpose();
  }
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix4d> eig(q_sum);
  const Eigen::Vector4d v = eig.eigenvectors().col(3);
  Eigen::Isometry3d mount = Eigen::Isometry3d::Identity();
  mount.linear() = Eigen::Quaterniond(v(0), v(1), v(2), v(3)).normalized().toRotationMatrix();
  mount.translation() = t / static_cast<double>(samples.size());
  return mount;
}

/// The board points the refinement compares: its centre and four corners of a square of half size h.
std::vector<Eigen::Vector3d> board_points(double h) {
  return {{0, 0, 0}, {h, h, 0}, {-h, h, 0}, {-h, -h, 0}, {h, -h, 0}};
}

/// Residuals of all samples' board points, camera frame, metres (camera then mount perturbed on the right).
Eigen::VectorXd residuals(const std::vector<HandEyeSample>& samples, const std::vector<Eigen::Vector3d>& points,
                          const Eigen::Isometry3d& base_camera, const Eigen::Isometry3d& tool_board) {
  Eigen::VectorXd r(static_cast<Eigen::Index>(samples.size() * points.size() * 3));
  Eigen::Index k = 0;
  const Eigen::Isometry3d camera_base = base_camera.inverse();
  for (const HandEyeSample& s : samples) {
    const Eigen::Isometry3d predicted = camera_base * s.pose_base_tool * tool_board;
    for (const Eigen::Vector3d& p : points) {
      r.segment<3>(k) = predicted * p - s.pose_camera_board * p;
      k += 3;
    }
  }
  return r;
}

/// Gauss-Newton on the camera's pose and the board's mount together (numerical Jacobian; 12 unknowns).
void refine(const std::vector<HandEyeSample>& samples, double half_size, Eigen::Isometry3d& base_camera,
            Eigen::Isometry3d& tool_board) {
  const std::vector<Eigen::Vector3d> points = board_points(half_size);
  constexpr double kStep = 1e-7;
  for (int iteration = 0; iteration < 20; ++iteration) {
    const Eigen::VectorXd r0 = residuals(samples, points, base_camera, tool_board);
    Eigen::MatrixXd j(r0.size(), 12);
    for (int c = 0; c < 12; ++c) {
      Eigen::Matrix<double, 6, 1> d = Eigen::Matrix<double, 6, 1>::Zero();
      d(c % 6) = kStep;
      const Eigen::Isometry3d cam = c < 6 ? base_camera * exp_motion(d) : base_camera;
      const Eigen::Isometry3d mount = c < 6 ? tool_board : tool_board * exp_motion(d);
      j.col(c) = (residuals(samples, points, cam, mount) - r0) / kStep;
    }
    const Eigen::Matrix<double, 12, 1> step = (j.transpose() * j).ldlt().solve(-j.transpose() * r0);
    if (!step.allFinite()) return;
    base_camera = base_camera * exp_motion(step.head<6>());
    tool_board = tool_board * exp_motion(step.tail<6>());
    if (step.norm() < 1e-12) return;
  }
}

void to_cv(const Eigen::Isometry3d& t, cv::Mat& r, cv::Mat& v) {
  Eigen::Matrix3d rot = t.linear();
  Eigen::Vector3d tr = t.translation();
  cv::eigen2cv(rot, r);
  cv::eigen2cv(tr, v);
}

}  // namespace

const char* hand_eye_code(HandEyeStatus status) {
  switch (status) {
    case HandEyeStatus::kOk: return "OK";
    case HandEyeStatus::kTooFewPoses: return "TOO_FEW_POSES";
    case HandEyeStatus::kDegenerate: return "DEGENERATE_POSES";
    case HandEyeStatus::kResidualTooLarge: return "HIGH_RESIDUAL";
  }
  return "UNKNOWN";
}

double rotation_axis_spread(const std::vector<Eigen::Isometry3d>& poses) {
  Eigen::Matrix3d m = Eigen::Matrix3d::Zero();
  for (std::size_t i = 0; i < poses.size(); ++i) {
    for (std::size_t j = i + 1; j < poses.size(); ++j) {
      const Eigen::AngleAxisd relative(poses[i].linear().transpose() * poses[j].linear());
      if (relative.angle() < kMinPairAngleRad) continue;
      m += relative.axis() * relative.axis().transpose();
    }
  }
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(m);
  const double largest = eig.eigenvalues()(2);
  return largest > 0.0 ? eig.eigenvalues()(1) / largest : 0.0;
}

HandEyeStatus solve_eye_to_hand(const std::vector<HandEyeSample>& samples, const HandEyeLimits& limits,
                                HandEyeResult& out, std::string& why) {
  out = HandEyeResult{};
  out.samples = static_cast<int>(samples.size());
  char text[320];
  if (out.samples < std::max(3, limits.min_samples)) {
    std::snprintf(text, sizeof text, "%d poses with the board seen; at least %d are needed", out.samples,
                  std::max(3, limits.min_samples));
    why = text;
    return HandEyeStatus::kTooFewPoses;
  }
  std::vector<Eigen::Isometry3d> tools;
  for (const HandEyeSample& s : samples) tools.push_back(s.pose_base_tool);
  out.axis_spread = rotation_axis_spread(tools);
  if (out.axis_spread < limits.min_axis_spread) {
    std::snprintf(text, sizeof text,
                  "the tool's rotations between the %d poses turn about one axis (axis spread %.3f, at least %.3f "
                  "needed): the camera's pose is not determined",
                  out.samples, out.axis_spread, limits.min_axis_spread);
    why = text;
    return HandEyeStatus::kDegenerate;
  }
  // Eye-to-hand with OpenCV's eye-in-hand solver: the base in the tool's frame for "gripper to base",
  // and the answer is the camera in the base.
  std::vector<cv::Mat> r_tool_base, t_tool_base, r_camera_board, t_camera_board;
  for (const HandEyeSample& s : samples) {
    cv::Mat r, t;
    to_cv(s.pose_base_tool.inverse(), r, t);
    r_tool_base.push_back(r);
    t_tool_base.push_back(t);
    to_cv(s.pose_camera_board, r, t);
    r_camera_board.push_back(r);
    t_camera_board.push_back(t);
  }
  cv::Mat r_base_camera, t_base_camera;
  cv::calibrateHandEye(r_tool_base, t_tool_base, r_camera_board, t_camera_board, r_base_camera, t_base_camera,
                       cv::CALIB_HAND_EYE_PARK);
  Eigen::Matrix3d rot;
  Eigen::Vector3d tr;
  cv::cv2eigen(r_base_camera, rot);
  cv::cv2eigen(t_base_camera, tr);
  out.pose_base_camera.linear() = Eigen::Quaterniond(rot).normalized().toRotationMatrix();
  out.pose_base_camera.translation() = tr;
  out.pose_tool_board = mean_mount(samples, out.pose_base_camera);
  refine(samples, limits.board_half_size_m, out.pose_base_camera, out.pose_tool_board);

  double position_sq = 0.0, rotation_sq = 0.0;
  for (const HandEyeSample& s : samples) {
    const Eigen::Isometry3d predicted = out.pose_base_camera.inverse() * s.pose_base_tool * out.pose_tool_board;
    const double dp = (predicted.translation() - s.pose_camera_board.translation()).norm();
    const double dr = rotation_angle(predicted.linear().transpose() * s.pose_camera_board.linear()) / kDeg;
    out.position_residual_m.push_back(dp);
    out.rotation_residual_deg.push_back(dr);
    position_sq += dp * dp;
    rotation_sq += dr * dr;
  }
  out.position_rms_m = std::sqrt(position_sq / out.samples);
  out.rotation_rms_deg = std::sqrt(rotation_sq / out.samples);
  if (!(out.position_rms_m <= limits.max_position_rms_m) || !(out.rotation_rms_deg <= limits.max_rotation_rms_deg)) {
    std::snprintf(text, sizeof text,
                  "the solution leaves residuals of %.2f mm and %.3f deg RMS over %d poses (limits %.2f mm, %.3f deg): "
                  "the board moved on the tool, the robot's poses are off, or the detections are poor",
                  out.position_rms_m * 1e3, out.rotation_rms_deg, out.samples, limits.max_position_rms_m * 1e3,
                  limits.max_rotation_rms_deg);
    why = text;
    return HandEyeStatus::kResidualTooLarge;
  }
  why.clear();
  return HandEyeStatus::kOk;
}

std::vector<Eigen::Isometry3d> plan_calibration_poses(const CalibrationPoseRequest& request) {
  const Eigen::Vector3d camera_at = request.pose_base_camera.translation();
  const Eigen::Vector3d toward_camera = (camera_at - request.centre_base).normalized();
  // The board facing the camera, upright in the image: z to the camera, x along the camera's x.
  const Eigen::Vector3d camera_x = request.pose_base_camera.linear().col(0);
  const Eigen::Vector3d x = (camera_x - camera_x.dot(toward_camera) * toward_camera).normalized();
  Eigen::Matrix3d facing;
  facing.col(0) = x;
  facing.col(2) = toward_camera;
  facing.col(1) = toward_camera.cross(x);

  const Eigen::Matrix3d k = request.camera.camera_matrix();
  const Eigen::Isometry3d camera_base = request.pose_base_camera.inverse();
  auto in_view = [&](const Eigen::Isometry3d& base_board) {
    for (const Eigen::Vector3d& corner : request.board_corners) {
      const Eigen::Vector3d p = camera_base * (base_board * corner);
      if (p.z() <= 0.05) return false;
      const Eigen::Vector3d uv = k * (p / p.z());
      if (uv.x() < request.margin_px || uv.y() < request.margin_px ||
          uv.x() > request.camera.width_px - request.margin_px || uv.y() > request.camera.height_px - request.margin_px)
        return false;
    }
    return true;
  };

  std::vector<Eigen::Isometry3d> poses;
  constexpr double kGolden = 2.399963229728653;  // the golden angle: successive candidates spread evenly
  for (int c = 0; c < 16 * std::max(1, request.count) && static_cast<int>(poses.size()) < request.count; ++c) {
    const double phase = c * kGolden;
    const double reach = std::sqrt((c % 8 + 0.5) / 8.0);
    const Eigen::Vector3d offset = facing * Eigen::Vector3d(request.spread_m * reach * std::cos(phase),
                                                            request.spread_m * reach * std::sin(phase),
                                                            request.spread_m * 0.5 * std::sin(1.7 * phase));
    // Tilt about an in-plane axis that turns from candidate to candidate, and a turn about the normal.
    const double tilt = request.tilt_deg * kDeg * (0.5 + 0.5 * ((c * 7) % 5) / 4.0);
    const Eigen::Vector3d tilt_axis = facing * Eigen::Vector3d(std::cos(1.3 * phase), std::sin(1.3 * phase), 0.0);
    const double turn = request.tilt_deg * kDeg * std::sin(2.1 * phase);
    Eigen::Isometry3d base_board = Eigen::Isometry3d::Identity();
    base_board.linear() = Eigen::AngleAxisd(tilt, tilt_axis) * facing * Eigen::AngleAxisd(turn, Eigen::Vector3d::UnitZ());
    base_board.translation() = request.centre_base + offset;
    if (!in_view(base_board)) continue;
    const Eigen::Isometry3d base_tool = base_board * request.pose_tool_board.inverse();
    if (request.reachable && !request.reachable(base_tool)) continue;
    poses.push_back(base_tool);
  }
  return poses;
}

}  // namespace rigger::vision
