#pragma once
/// @file
/// The geometry of calibrating a fixed camera with a board on the robot's tool (CalibrateCamera): the tool
/// poses that show the board to the camera, whether a set of poses can determine the camera, and the
/// camera's pose solved from pose pairs. Pure (Eigen): no DDS, no devices.
///
/// Frames: base = the robot's base, tool = the arm's tool frame, board = the board's frame (its printed face
/// +z), camera = the camera's optical frame (z forward, x right, y down). Lengths in m, angles in rad unless
/// a name says otherwise.
///
/// The solve is a direct least-squares over the pose pairs: the camera's pose in the base (X = T_camera_base)
/// and the board's mount on the tool (Y = T_tool_board) that minimise the distances between the board's
/// corners as the camera saw them (T_camera_board_i) and as the arm put them (X T_base_tool_i Y), started
/// from the cell file's mount, by Gauss-Newton. Corner distances weigh the board's orientation by its size,
/// as the tracker's measurement of it is; the mount is solved too, since a real board is mounted only as
/// well as it was fitted. OpenCV's closed forms (calibrateRobotWorldHandEye: Shah, Li) minimise an algebraic
/// error that weighs rotation against translation arbitrarily; with the mount as a starting point none is
/// needed.

#include <string>
#include <vector>

#include <Eigen/Geometry>
#include <nlohmann/json.hpp>

#include "rigger/cell_config/cell_types.hpp"

namespace rigger::skill_executor::calibration {

/// What the tool poses are planned from.
struct PosePlanInput {
  Eigen::Isometry3d pose_base_tool_now = Eigen::Isometry3d::Identity();  ///< where the arm holds the board now
  Eigen::Isometry3d pose_tool_board = Eigen::Isometry3d::Identity();     ///< the board's mount (cell file)
  Eigen::Isometry3d pose_base_camera = Eigen::Isometry3d::Identity();    ///< where the cell says the camera is
  cell::CameraIntrinsics camera;                                         ///< for the view check
  double board_size_m = 0.3;                                             ///< the printed face's larger edge
  int count = 10;                                                        ///< poses wanted
  double tilt_rad = 0.26;  ///< how far each pose turns the board off facing the camera
  double shift_m = 0.05;   ///< how far each pose moves the board in its plane
  double max_recentre_m = 0.2;  ///< how far the poses' centre may move from where the arm holds the board
};

/// Up to `count` tool poses (T_base_tool) about where the arm holds the board now. Their centre is the
/// board's, moved across the line of sight (by at most max_recentre_m) until the board facing the camera,
/// grown by shift_m on every side, lies in the picture. The first pose turns the board to face the camera
/// there; each further one tilts it by tilt_rad about an axis in its plane that turns by the golden angle
/// from pose to pose, spins it by ±tilt_rad/2 about its normal and shifts it by shift_m in its plane. A pose
/// counts when the whole board is in the picture (its four corners through the lens, 5 % of the picture in
/// from its edges; the cell's camera pose and intrinsics) and faces the camera within 60°; the others are
/// left out. Whether the arm reaches a pose, and whether the cell hides the board there, is for the arm and
/// the tracker to say.
std::vector<Eigen::Isometry3d> plan_poses(const PosePlanInput& in);

/// Where a point in the camera's optical frame (z > 0) lands in its picture through the lens, in pixels:
/// OpenCV's model (radial, tangential, rational and thin prism terms; not a tilted sensor's).
Eigen::Vector2d project_through_lens(const cell::CameraIntrinsics& camera, const Eigen::Vector3d& point_camera);

/// How far apart the rotation axes of the relative motions between the tool poses are, in degrees: 0 when
/// every rotation between two poses is about one axis (the camera's position along it is then
/// undetermined), about 45 and more for rotations about two perpendicular axes. Pairs turned by less
/// than 2° are not counted.
double axis_spread_deg(const std::vector<Eigen::Isometry3d>& poses_base_tool);

/// One pose of the calibration.
struct PosePair {
  Eigen::Isometry3d pose_base_tool = Eigen::Isometry3d::Identity();     ///< the arm's tool (its state)
  Eigen::Isometry3d pose_camera_board = Eigen::Isometry3d::Identity();  ///< the board as the camera saw it
};

/// How far one pose's board, as the solution puts it, is from where the camera saw it.
struct PoseResidual {
  double mm = 0.0;
  double deg = 0.0;
};

struct Solution {
  Eigen::Isometry3d pose_base_camera = Eigen::Isometry3d::Identity();
  Eigen::Isometry3d pose_tool_board = Eigen::Isometry3d::Identity();  ///< the mount as solved
  std::vector<PoseResidual> residuals;                                ///< per pose, in the order given
  double rms_mm = 0.0;
  double rms_deg = 0.0;
  double max_mm = 0.0;
  double max_deg = 0.0;
  int iterations = 0;
};

/// The camera's pose and the board's mount from at least 3 pose pairs (see the file comment), with the
/// residuals. `mount_guess` starts the solve; `board_size_m` places the corners. The caller checks
/// axis_spread_deg() first: with degenerate poses the result is meaningless.
/// @throws std::invalid_argument for fewer than 3 pairs.
Solution solve(const std::vector<PosePair>& pairs, const Eigen::Isometry3d& mount_guess, double board_size_m);

/// The angle of a rotation, in degrees.
double angle_deg(const Eigen::Matrix3d& rotation);

/// A pose as the cell file writes it: {"position_m": [x, y, z], "rpy_deg": [roll, pitch, yaw]}.
nlohmann::json pose_json(const Eigen::Isometry3d& pose);

}  // namespace rigger::skill_executor::calibration
