#pragma once
/// @file
/// CalibrateCamera: finds where the cell's camera really is with the calibration board on the robot's tool,
/// and writes it as a cell revision.
///
///   read_cell ──▶ move ──▶ measure ──▶ (next pose: move) … ──▶ return ──▶ solve ──▶ check ──▶ apply ──▶ SUCCESS
///
/// read_cell: the running revision (the camera's drawn pose and intrinsics, the robot's base, the board's
/// mount) and the arm's tool pose; plans `poses` tool poses and spares (half as many again, at least 2) about
/// it (camera_calibration.hpp: moved up to 20 cm across the line of sight so that the whole board is in the
/// picture, the board turned to face the camera, then tilted about varied axes in its plane, spun and
/// shifted). A pose counts when the whole board is in the picture (through the lens, 5 % in from its edges)
/// and faces the camera within 60°. move: a Cartesian motion to the next pose; a pose the arm refuses as
/// UNREACHABLE is skipped. measure: the arm's tool pose (its state after the motion) and TRACK_ONCE of the
/// board (robot/calibration_board, measured in the camera's frame), asked again after 2.5 s without an
/// answer and after an image in which the board was not found, for at most view_timeout_s; the tracker's
/// not-tracked answer to it (after its own 2 s wait) skips the pose at once. Spares stand in for skipped
/// poses until `poses` were seen or none is left; each skipped pose and why is in the record's `skipped`.
/// return: the arm back where it started. solve: the camera's pose and the board's mount by least squares
/// over the pose pairs. check: the new document (the camera's pose, and attributes.calibration, the record)
/// as a dry run, which must change the camera and nothing else. apply: the revision, its `who`
/// "CalibrateCamera" (and for whom), its comment the figures.
///
/// Failure codes (no revision is proposed for any of them): DEVICE_UNAVAILABLE; CELL_UNAVAILABLE (the
/// running cell cannot be read, has no such camera, or the robot no calibration_board); NO_POSES_IN_VIEW
/// (fewer than 3 planned poses keep the board in the picture); POSES_UNREACHABLE (the arm reached fewer
/// than 3); BOARD_NOT_SEEN (the camera saw the board at fewer than 3 poses); DEGENERATE_POSES (the seen
/// poses turn about one axis only: axis spread under 5°); RESIDUAL_TOO_LARGE (with the figures);
/// MOTION_FAILED, MOTION_ABORTED, TIMEOUT, ROBOT_STATE_STALE; WORLD_UPDATE_REJECTED (the world model
/// refused the revision: its code and message), WORLD_UNREACHABLE.
///
/// Safe stops: the robot is stopped in move and return; the other states command nothing. Pausable: a pause
/// stops the arm in move and return, and resume asks for the same pose again; the other states run on.
/// Params: see describe(). Claims "robot" and "camera" (the controller runs nothing else that needs either
/// meanwhile; the world model lets the revision of the camera through, as it comes from the holder's executor).

#include <optional>
#include <string>
#include <vector>

#include "camera_calibration.hpp"
#include "rigger/cell_config/cell_file.hpp"
#include "rigger/skill_sdk/cell_devices.hpp"
#include "rigger/skill_sdk/skill.hpp"
#include "sdk.hpp"

namespace rigger::skill_executor {

class CalibrateCameraSkill final : public Skill {
 public:
  static const skill::SkillDescription& describe();
  CalibrateCameraSkill();

  /// TRACK_ONCE is sent again after this long without an answer (a pose lost on the best-effort topic). Longer
  /// than the tracker's own 2 s wait for a TRACK_ONCE, which it ends with a not-tracked pose (answered at once):
  /// sent more often, each command restarted that wait.
  static constexpr std::chrono::milliseconds kRetryPeriod{2500};
  /// A not-tracked answer stamped this long after the first TRACK_ONCE of a pose skips the pose at once: the
  /// tracker looked at its images for its own wait (2 s) without a good pose of the board. An earlier one
  /// (one image without the board, while it tracks continuously) is asked again.
  static constexpr std::chrono::milliseconds kNotSeenAfter{1500};
  static constexpr std::chrono::seconds kWorldTimeout{10};
  static constexpr std::chrono::seconds kStateTimeout{1};
  static constexpr std::chrono::seconds kStopTimeout{3};
  /// The fewest pose pairs a solve takes; the smallest axis spread it accepts.
  static constexpr int kMinPoses = 3;
  static constexpr double kMinAxisSpreadDeg = 5.0;

 private:
  void read_cell();
  /// The arm's tool pose now → plan().
  void read_arm();
  void plan(const RobotSnapshot& state);
  void move();
  void measure();
  void send_once();
  void on_sample(const TrackedObjectSample& sample);
  void next_pose(const std::string& skipped_because);
  void return_to_start();
  void solve();
  void check();
  void apply();
  void stop_robot(const SafeStopDone& done);
  /// The running document with the camera at `pose_world_camera` and the calibration record.
  nlohmann::json revised_document() const;

  std::string camera_id_;
  std::string board_id_;
  CellDocument running_;
  std::optional<cell::CellFile> cell_;
  Eigen::Isometry3d pose_world_base_ = Eigen::Isometry3d::Identity();
  Eigen::Isometry3d pose_tool_board_ = Eigen::Isometry3d::Identity();
  double board_size_m_ = 0.0;
  Eigen::Isometry3d start_tool_ = Eigen::Isometry3d::Identity();
  int wanted_ = 0;  ///< the poses asked for; planned_ holds spares beyond them
  std::vector<Eigen::Isometry3d> planned_;
  std::size_t next_ = 0;
  int reached_ = 0;
  std::vector<std::string> skipped_;
  std::optional<Eigen::Isometry3d> tool_now_;
  std::optional<WallTime> first_command_;
  WallTime last_command_;
  std::uint64_t retry_timer_ = 0;
  std::vector<calibration::PosePair> pairs_;
  calibration::Solution solution_;
  double spread_deg_ = 0.0;
  Eigen::Isometry3d pose_world_camera_ = Eigen::Isometry3d::Identity();
  std::string summary_;
  std::string document_;  ///< the revision proposed: checked as a dry run, then applied
};

}  // namespace rigger::skill_executor
