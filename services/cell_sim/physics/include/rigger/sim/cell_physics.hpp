#pragma once
// The physics of the simulated cell (MuJoCo): overhead crane with a swinging load, KUKA LBR iiwa
// 14 R820 with its controller, magnetic gripper, wrist F/T sensor, target fixture.  No DDS, no
// rendering, no logging: the cell_sim process drives it and publishes what it reports.
//
// Frames: world (cell JSON, z up); crane frame (x bridge, y trolley); robot base frame (JSON
// "robot" pose); flange; tool (magnet face centre, flange axes, z out of the face).

#include <chrono>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include "rigger/sim/cell_geometry.hpp"
#include "rigger/sim/crane_drive.hpp"
#include "rigger/sim/magnet_grip.hpp"
#include "rigger/sim/physics_types.hpp"

struct mjModel_;  // MuJoCo's compiled model (mujoco/mjmodel.h), for a renderer's copy

namespace rigger::sim {

/// What poses every body of the model: the joint positions and the mocap bodies' poses (MuJoCo's
/// qpos, mocap_pos, mocap_quat). A renderer with its own copy of the model runs its kinematics on it.
struct KinematicState {
  std::vector<double> qpos;
  std::vector<double> mocap_pos;
  std::vector<double> mocap_quat;
};

/// The MJCF cannot be loaded or lacks an element the physics needs.  what() names the file and
/// the element (or quotes MuJoCo's compiler message).
class PhysicsModelError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// The devices' MJCF written for rigger (models/cell.xml of this folder: crane, robot, gripper; the cell's
/// objects are generated into it from the cell file), installed as cell_sim/cell.xml in the data folder
/// (rigger/base/install.hpp), where this looks for it.
std::filesystem::path default_model_path();

/// The arm's start pose: elbow up, the tool pointing along the base's +x with tool x down, at about
/// (0.68, 0, 0.46) m in the base frame (A1..A7 = 0, 22.5, 0, -113.8, 0, -46.3, 0 deg).
JointVector ready_joint_positions();

/// Gaussian noise added to every F/T sample (standard deviations; 0 = exact).
struct WrenchNoise {
  double force_stddev_n = 0.0;
  double torque_stddev_nm = 0.0;
};

/// Cartesian limits of the arm's controller (tool point, base frame).
struct CartesianLimits {
  double linear_speed_mps = 0.5;
  double angular_speed_rad_per_s = 1.0;
  double linear_accel_mps2 = 1.0;
  double angular_accel_rad_per_s2 = 2.0;
};

/// Joint limits the arm's controller enforces: the iiwa's published ones, with the position range
/// narrowed by a margin (software limits inside the hardware ones).
struct ArmLimits {
  JointVector position_min_rad = JointVector::Zero();
  JointVector position_max_rad = JointVector::Zero();
  JointVector speed_max_rad_per_s = JointVector::Zero();
  JointVector accel_max_rad_per_s2 = JointVector::Zero();
  JointVector torque_max_nm = JointVector::Zero();
  /// The hardware range (the MJCF joint range): never exceeded.
  JointVector hard_position_max_rad = JointVector::Zero();
};

/// Outcome of an inverse kinematics query.
struct IkResult {
  bool converged = false;
  JointVector position_rad = JointVector::Zero();
  double position_error_m = 0.0;
  double orientation_error_rad = 0.0;
  int iterations = 0;
};

/// The magnet's holding as a stiff 6-axis spring-damper between face and load (see README).
struct MagnetSpring {
  double stiffness_n_per_m = 1.0e5;
  double damping_n_s_per_m = 2000.0;
  double rotational_stiffness_nm_per_rad = 10000.0;
  double rotational_damping_nm_s_per_rad = 40.0;
  /// Contact counts as "flat on the load" within this angle between tool z and the face normal.
  double max_contact_angle_rad = 5.0 * 3.14159265358979323846 / 180.0;
};

struct CellPhysicsOptions {
  std::filesystem::path model_path = default_model_path();
  WrenchNoise wrench_noise;
  std::uint64_t noise_seed = 1;
  JointVector initial_joint_positions_rad = ready_joint_positions();
  /// Software joint limits sit this far inside the hardware limits (rad).
  double joint_limit_margin_rad = 1.0 * 3.14159265358979323846 / 180.0;
  CartesianLimits cartesian_limits;
  /// A twist command is applied for at most this long (simulated time) unless renewed.
  std::chrono::nanoseconds twist_timeout = std::chrono::milliseconds(200);
  RopeParams rope;
  /// Shear, peel and twist capacities; the holding force itself comes from the cell JSON.
  MagnetCapacity magnet_capacity;
  MagnetSpring magnet_spring;
};

/// The simulated cell's physics.  Commands take effect at the next step; getters report the
/// state after the last step.  Not thread-safe: one thread owns it (the caller serialises).
/// Steady-state calls never throw: they return CommandResult or clamp.
class CellPhysics {
 public:
  /// Loads the MJCF and writes the cell geometry into it.  Throws PhysicsModelError (MJCF) or
  /// CellGeometryError (geometry that does not fit the model).
  explicit CellPhysics(const CellGeometry& cell, const CellPhysicsOptions& options = {});
  ~CellPhysics();
  CellPhysics(CellPhysics&&) noexcept;
  CellPhysics& operator=(CellPhysics&&) noexcept;
  CellPhysics(const CellPhysics&) = delete;
  CellPhysics& operator=(const CellPhysics&) = delete;

  // ---- time ------------------------------------------------------------------------------
  /// Simulated time since start (an exact multiple of the timestep).
  [[nodiscard]] std::chrono::nanoseconds sim_time() const;
  /// Physics timestep (1 ms).
  [[nodiscard]] std::chrono::nanoseconds timestep() const;
  /// Advances by `duration`, rounded to whole timesteps; non-positive does nothing.
  void step(std::chrono::nanoseconds duration);
  /// Advances to the last whole timestep not later than `sim_time` (plus half a step).
  void advance_to(std::chrono::nanoseconds sim_time);

  // ---- crane -----------------------------------------------------------------------------
  /// Velocity setpoints (bridge, trolley, hoist; m/s, hoist positive = lowering), already limited
  /// by the PLC.  Ignored (held at zero) while frozen.  Rejects non-finite values and magnitudes
  /// above 10 m/s.
  CommandResult set_crane_velocity(const Eigen::Vector3d& setpoint_mps);
  /// Freeze (e-stop): all axes brake to a standstill and hold until unfrozen; setpoints are
  /// cleared, so unfreezing does not restart motion.
  void set_crane_frozen(bool frozen);
  [[nodiscard]] CraneState crane_state() const;

  // ---- robot -----------------------------------------------------------------------------
  /// Synchronized trapezoidal joint motion to `goal_rad` at `speed_fraction` (0, 1] of the joint
  /// speed limits.  Rejected outside the software joint limits.  A moving arm first stops.
  CommandResult move_joints(const JointVector& goal_rad, double speed_fraction = 1.0);
  /// Straight-line tool motion (position linear, orientation by slerp) to `goal_base_tool`, at
  /// `speed_fraction` of the Cartesian limits.  Rejected when inverse kinematics finds no
  /// configuration for the goal.  Fails at run time if the path leaves the workspace.
  CommandResult move_tool(const Eigen::Isometry3d& goal_base_tool, double speed_fraction = 1.0);
  /// Resolved-rate velocity of the tool point (base frame), held for the twist timeout unless
  /// renewed; scaled down to the Cartesian limits; joint limits enforced.  Zero stops the arm.
  CommandResult set_tool_twist(const Twist& twist_base);
  /// Decelerate to rest and hold; an active motion ends as Stopped. A twist stream stops on its path (the
  /// tool's twist ramps to zero at the Cartesian acceleration limit); a point-to-point motion brakes each
  /// joint at its acceleration limit.
  void stop_robot();
  [[nodiscard]] RobotState robot_state() const;
  [[nodiscard]] const ArmLimits& arm_limits() const;
  /// Tool pose in the base frame for a joint configuration (forward kinematics).
  [[nodiscard]] Eigen::Isometry3d tool_pose_for(const JointVector& q_rad) const;
  /// Joint configuration (within the software limits) placing the tool at `pose_base_tool`;
  /// tries `seed` (default: the current reference) and a few standard seeds.
  [[nodiscard]] IkResult solve_ik(const Eigen::Isometry3d& pose_base_tool,
                                  const JointVector* seed = nullptr) const;

  // ---- gripper and wrist F/T sensor ------------------------------------------------------
  void set_gripper_energized(bool energized);
  [[nodiscard]] GripperState gripper_state() const;
  /// The wrist sensor as a real one reads: the wrench the gripper side exerts on the flange
  /// (gripper weight and inertia included), in the tool frame, torque about the tool point, with
  /// the configured noise.  Pulling the tool away from the flange along tool +z reads +z.
  [[nodiscard]] Wrench wrench_tool() const;
  /// wrench_tool() minus the gripper's static weight (what a controller with tool-load data
  /// reports as the external wrench).
  [[nodiscard]] Wrench external_wrench_tool() const;

  // ---- ground truth ----------------------------------------------------------------------
  [[nodiscard]] Eigen::Isometry3d pose_world_load() const;
  [[nodiscard]] Twist twist_world_load() const;
  [[nodiscard]] Eigen::Isometry3d pose_world_target() const;
  /// The part's box centre and its table's top-face centre; nullopt when the cell has no part.
  [[nodiscard]] std::optional<Eigen::Isometry3d> pose_world_part() const;
  [[nodiscard]] std::optional<Eigen::Isometry3d> pose_world_part_fixture() const;
  [[nodiscard]] Eigen::Isometry3d pose_world_robot_base() const;
  /// The frame of the object entity `id` (any object of the cell file); nullopt for an unknown id.
  [[nodiscard]] std::optional<Eigen::Isometry3d> pose_world_object(std::string_view id) const;
  /// The model's names of the objects' bodies, in the cell file's order (one per object entity).
  [[nodiscard]] std::vector<std::string> object_bodies() const;
  [[nodiscard]] const CellGeometry& geometry() const;

  // ---- cell revisions --------------------------------------------------------------------
  /// Puts the free object `id` at `pose_world_object` (its entity frame in the world), at rest: its free
  /// joint's position set, its velocities zeroed, positions and contacts recomputed, as a person who
  /// moves a part on the table leaves it. Refused, with the reason in the message: a non-finite pose or a
  /// rotation that is not one (RejectedNonFinite, RejectedOutOfRange); an unknown or static object
  /// (RejectedNotFree); the object the magnet holds or the crane's load (RejectedHeld). Not thread-safe:
  /// call on the thread that steps the physics.
  CommandResult move_free_object(std::string_view id, const Eigen::Isometry3d& pose_world_object);
  /// What move_free_object would answer, changing nothing.
  [[nodiscard]] CommandResult can_move_free_object(std::string_view id, const Eigen::Isometry3d& pose_world_object) const;

  // ---- a model built anew (a revision that adds, removes or reshapes objects) -----------------
  /// Continues the cell where `running` (its physics until now, built from the cell before) stands, so that
  /// this physics, built from the new cell, can replace it between two steps: simulated time, every joint
  /// both models have by name (arm, crane axes, sway, rope, load swivel, each persisting free object: position
  /// and velocity), the crane's drives, rope and load cell, the arm's controller, the gripper's state and
  /// holding force, injected forces, the wrist sensor's last reading and noise, MuJoCo's warning counts.
  /// Objects only this model has stay at their pose of the new cell, at rest; static objects are where the
  /// new cell puts them. Refused, changing nothing here or in `running`: while the arm moves or brakes (not
  /// holding still), while the magnet holds something, when the crane's load is another object, or when the
  /// robot's base or the crane stands elsewhere (RejectedHeld, RejectedOutOfRange). Call on the thread that
  /// steps `running`; `running` is left as it was (the caller drops it).
  CommandResult continue_from(const CellPhysics& running);

  // ---- rendering -------------------------------------------------------------------------
  /// A copy of the compiled model (mj_copyModel) for a renderer on another thread: it shares
  /// nothing with the physics, so the renderer needs no lock, only a KinematicState per frame.
  /// Freed by mj_deleteModel when the last owner lets go.
  [[nodiscard]] std::shared_ptr<const mjModel_> copy_model() const;
  /// The current joint and mocap positions into `state` (its vectors are reused: no allocation
  /// after the first call).
  void copy_kinematic_state(KinematicState& state) const;

  // ---- fault injection -------------------------------------------------------------------
  /// Changes the magnet's holding force at run time (N, >= 0): a weak or failing grasp.
  CommandResult set_gripper_holding_force(double holding_force_n);
  /// A constant force (world frame, N) on the load's centre until changed; zero removes it.
  CommandResult set_load_external_force(const Eigen::Vector3d& force_world_n);

  [[nodiscard]] PhysicsDiagnostics diagnostics() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace rigger::sim
