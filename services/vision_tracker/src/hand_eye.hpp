#pragma once
/// @file
/// The camera's pose in the robot's base from a board the robot carries (eye-to-hand calibration):
/// the poses to show the board in, the solve (OpenCV's calibrateHandEye, then a joint least-squares
/// refinement of the camera and the board's mount on the tool), and the checks that make a result
/// trustworthy — enough poses, rotations about more than one axis, residuals under a limit.
/// No DDS, no robot: the caller moves the robot and measures the board (vision_tracker's estimator).

#include <Eigen/Geometry>

#include <functional>
#include <string>
#include <vector>

#include "tracker_config.hpp"

namespace rigger::vision {

/// One pose of a calibration: the tool in the robot's base (the robot's forward kinematics) and the
/// board in the camera's optical frame (one image), taken while the robot stood still.
struct HandEyeSample {
  Eigen::Isometry3d pose_base_tool = Eigen::Isometry3d::Identity();
  Eigen::Isometry3d pose_camera_board = Eigen::Isometry3d::Identity();
};

struct HandEyeLimits {
  int min_samples = 6;
  /// The rotations between the samples must turn about more than one axis: the second eigenvalue of
  /// the sum of their axes' outer products over the first must reach this (0: one axis, 1: two alike).
  double min_axis_spread = 0.1;
  /// The refined solution's residuals (RMS over the samples) must stay under these.
  double max_position_rms_m = 0.002;
  double max_rotation_rms_deg = 0.2;
  /// Half the board's extent: the refinement weighs rotation by the corners' displacement.
  double board_half_size_m = 0.1;
};

struct HandEyeResult {
  Eigen::Isometry3d pose_base_camera = Eigen::Isometry3d::Identity();
  /// The board on the tool, as solved (the mount need not be known exactly).
  Eigen::Isometry3d pose_tool_board = Eigen::Isometry3d::Identity();
  int samples = 0;
  double axis_spread = 0.0;
  /// Per sample: the measured board pose against the one the solution predicts.
  std::vector<double> position_residual_m;
  std::vector<double> rotation_residual_deg;
  double position_rms_m = 0.0;
  double rotation_rms_deg = 0.0;
};

enum class HandEyeStatus {
  kOk,
  kTooFewPoses,
  /// All rotations about one axis (or hardly any rotation): the camera's pose is not determined.
  kDegenerate,
  /// Solved, but the residuals exceed the limits: the result is in `out`, not to be used.
  kResidualTooLarge,
};

/// TOO_FEW_POSES, DEGENERATE_POSES, HIGH_RESIDUAL or OK: the codes a skill fails with.
const char* hand_eye_code(HandEyeStatus status);

/// Solves the camera in the robot's base from samples. `why` says what failed, with the figures.
HandEyeStatus solve_eye_to_hand(const std::vector<HandEyeSample>& samples, const HandEyeLimits& limits,
                                HandEyeResult& out, std::string& why);

/// The spread of the rotation axes between the poses (see HandEyeLimits::min_axis_spread); pairs
/// turned by less than 5 degrees do not count.
double rotation_axis_spread(const std::vector<Eigen::Isometry3d>& poses);

/// What choosing the calibration's poses needs: where the camera is believed to be (the cell file),
/// its intrinsics, where the board's centre should go, the board's mount on the tool and the robot's
/// reach.
struct CalibrationPoseRequest {
  CameraIntrinsics camera;
  Eigen::Isometry3d pose_base_camera = Eigen::Isometry3d::Identity();
  Eigen::Vector3d centre_base = Eigen::Vector3d::Zero();
  Eigen::Isometry3d pose_tool_board = Eigen::Isometry3d::Identity();
  /// The board's corners in its own frame (z out of the printed face).
  std::vector<Eigen::Vector3d> board_corners;
  int count = 12;
  /// Largest offset of the board's centre from centre_base, metres.
  double spread_m = 0.12;
  /// Largest tilt of the board away from facing the camera, degrees.
  double tilt_deg = 30.0;
  /// Every board corner at least this far inside the image, pixels.
  double margin_px = 40.0;
  /// Whether the robot can put its tool there; everything when empty.
  std::function<bool(const Eigen::Isometry3d& pose_base_tool)> reachable;
};

/// Up to request.count tool poses in the robot's base that show the whole board to the camera, tilted
/// about different axes, within reach; deterministic. Fewer when fewer candidates qualify.
std::vector<Eigen::Isometry3d> plan_calibration_poses(const CalibrationPoseRequest& request);

}  // namespace rigger::vision
