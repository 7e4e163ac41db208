#pragma once
/// @file
/// The simulated cell's real-time part: one thread owns the MuJoCo physics and the crane PLC
/// emulator and steps them at 1 kHz of simulated time, paced against the wall clock
/// (RealTimePacer). Commands arrive through a mutex-protected mailbox; what the cell reports leaves
/// through SimOutputs, called on the physics thread. No DDS here: the node implements SimOutputs.

#include <atomic>
#include <chrono>
#include <cstdint>
#include <memory>
#include <future>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <variant>
#include <vector>

#include "camera_worker.hpp"
#include "cell_revisions.hpp"
#include "cell_sim_config.hpp"
#include "command_gate.hpp"
#include "physics_crane_axes.hpp"
#include "rigger/base/logging.hpp"
#include "rigger/base/time.hpp"
#include "rigger/plc/plc_emulator.hpp"
#include "rigger/sim/cell_physics.hpp"
#include "rigger/sim/realtime_pacer.hpp"

namespace rigger::cell_sim {

// ---- commands (mailbox) ---------------------------------------------------------------------

/// A tool twist (tool point, robot base frame) that holds until `expires` (wall clock).
struct TwistCommand {
  sim::Twist twist_base;
  WallTime expires{};
  std::uint64_t seq = 0;
  std::string source;  ///< the writer's id (the TwistCommand's `source`), for the logs
};

enum class MotionKind { kJoint, kCartesian, kStop };

/// A point-to-point motion, or a stop.
struct MotionCommand {
  std::string motion_id;
  MotionKind kind = MotionKind::kStop;
  sim::JointVector joint_goal_rad = sim::JointVector::Zero();
  Eigen::Isometry3d goal_base_tool = Eigen::Isometry3d::Identity();
  double speed_fraction = 1.0;
  /// Simulated time the motion may take; zero: no limit.
  std::chrono::nanoseconds timeout{0};
};

struct GripperCommand {
  bool energize = false;
  std::uint64_t seq = 0;
};

/// Fault injection (rigger/sim/control).
enum class ControlKind { kEstop, kSetHoldingForce, kSetLoadForce, kPlcLink, kReset };

struct SimControlCommand {
  ControlKind kind = ControlKind::kReset;
  bool on = false;
  double value = 0.0;
  Eigen::Vector3d vector = Eigen::Vector3d::Zero();
  std::uint64_t seq = 0;
  std::string source;
};

/// A cell revision's moved objects (plan_revision), applied together or not at all: `done` gets an empty
/// string once every object is at its new pose, or which object could not be moved and why (nothing moved).
/// Settles who has a command its sender waits for: the physics thread takes it when it comes to it, or the
/// sender withdraws it when it gave up waiting. Exactly one of the two succeeds, so a command reported
/// refused for a timeout is never applied afterwards, and one the physics took is waited for to its end.
class CommandClaim {
 public:
  /// The physics thread: true when the command is still wanted (and now the physics thread's).
  bool take() { return settle(kTaken); }
  /// The sender: true when the physics thread had not taken it (it never will now).
  bool withdraw() { return settle(kWithdrawn); }

 private:
  enum State : int { kPending, kTaken, kWithdrawn };
  bool settle(State to) {
    int expected = kPending;
    return state_.compare_exchange_strong(expected, to);
  }
  std::atomic<int> state_{kPending};
};

struct ObjectMovesCommand {
  std::vector<ObjectMove> moves;
  std::shared_ptr<std::promise<std::string>> done;
  std::shared_ptr<CommandClaim> claim = std::make_shared<CommandClaim>();
};

/// What became of a ModelSwapCommand: empty `refusal` when the new model runs.
struct ModelSwapResult {
  std::string refusal;
  /// Wall time the physics thread spent in the step that swapped (the swap and the step after it).
  std::chrono::nanoseconds swap_step{0};
};

/// A cell revision that needs the model built anew (plan_revision's rebuild): `physics`, built from the new
/// cell off the physics thread, replaces the running one between two steps, continuing its state
/// (CellPhysics::continue_from), then `moves` are made on it; all or nothing. Refused while a motion or twist
/// runs or stops, and for whatever continue_from or a move refuses. `camera_renderer` (optional) renders the
/// new model from the first snapshot of it on.
struct ModelSwapCommand {
  std::shared_ptr<sim::CellPhysics> physics;
  sim::CellGeometry geometry;
  std::vector<ObjectMove> moves;
  RendererFactory camera_renderer;
  std::shared_ptr<std::promise<ModelSwapResult>> done;
  std::shared_ptr<CommandClaim> claim = std::make_shared<CommandClaim>();
};

using SimCommand =
    std::variant<TwistCommand, MotionCommand, GripperCommand, SimControlCommand, ObjectMovesCommand, ModelSwapCommand>;

// ---- reports (outputs) -----------------------------------------------------------------------

struct RobotReport {
  sim::RobotState state;
  bool estop = false;
  std::string fault;  ///< empty when none
  std::uint64_t last_command_seq = 0;
};

struct GripperReport {
  sim::GripperState state;
  std::uint64_t last_command_seq = 0;
};

enum class MotionPhase { kAccepted, kExecuting, kSucceeded, kFailed, kAborted };

struct MotionReport {
  std::string motion_id;
  MotionPhase phase = MotionPhase::kAccepted;
  std::string code;  ///< e.g. "UNREACHABLE", "TIMEOUT", "EMERGENCY_STOP"; empty on success
  std::string message;
};

/// One object's true pose: its entity id and the frame the cell file gives it, world frame.
struct ObjectTruth {
  std::string id;
  Eigen::Isometry3d pose_world_object = Eigen::Isometry3d::Identity();
};

/// True poses of every object of the cell, in the cell file's order (tests and benchmarks only).
struct GroundTruth {
  std::vector<ObjectTruth> objects;
  /// Objects the model no longer has since the last publication (a revision removed them): their
  /// instances are disposed.
  std::vector<std::string> removed;
};

/// The simulator's health, its PLC's registers and the crane's true state. Crane vectors in the
/// Modbus map's convention (z = hook height, up positive).
struct StatusReport {
  double sim_time_s = 0.0;
  std::uint64_t steps = 0;
  double real_time_factor_target = 1.0;
  double real_time_factor_measured = 0.0;
  std::uint64_t overruns = 0;
  int mujoco_warnings = 0;
  std::uint64_t camera_frames = 0;
  std::uint64_t camera_frames_dropped = 0;
  bool estop_pressed = false;
  bool plc_link_up = false;
  std::uint16_t plc_port = 0;
  int plc_clients = 0;
  std::uint16_t plc_status_word = 0;
  std::uint16_t plc_fault_code = 0;
  std::uint16_t plc_heartbeat = 0;
  std::uint16_t plc_control_word = 0;
  std::uint16_t gateway_heartbeat = 0;
  Eigen::Vector3d plc_setpoint_mps = Eigen::Vector3d::Zero();
  Eigen::Vector3d plc_drive_command_mps = Eigen::Vector3d::Zero();
  Eigen::Vector3d crane_position_m = Eigen::Vector3d::Zero();
  Eigen::Vector3d crane_velocity_mps = Eigen::Vector3d::Zero();
  double crane_load_kg = 0.0;
  Eigen::Vector2d crane_sway_rad = Eigen::Vector2d::Zero();
  double gripper_holding_force_n = 0.0;
  Eigen::Vector3d load_external_force_n = Eigen::Vector3d::Zero();
};

/// The answer to one SimControlCommand.
struct ControlResult {
  std::uint64_t seq = 0;
  std::string source;
  ControlKind kind = ControlKind::kReset;
  bool accepted = false;
  std::string message;
};

/// Where the physics thread's reports go. Called on the physics thread (publish_control_result also
/// from the thread calling SimRunner::submit for controls it can answer at once): implementations
/// must be quick, thread-safe, and must not throw.
class SimOutputs {
 public:
  virtual ~SimOutputs() = default;
  /// The wrist F/T sensor: tool frame, torque about the tool point.
  virtual void publish_wrench(const sim::Wrench& wrench_tool, WallTime stamp) = 0;
  virtual void publish_robot_state(const RobotReport& report, WallTime stamp) = 0;
  virtual void publish_gripper_state(const GripperReport& report, WallTime stamp) = 0;
  virtual void publish_motion_status(const MotionReport& report, WallTime stamp) = 0;
  virtual void publish_ground_truth(const GroundTruth& truth, WallTime stamp) = 0;
  virtual void publish_status(const StatusReport& status, WallTime stamp) = 0;
  virtual void publish_control_result(const ControlResult& result, WallTime stamp) = 0;
};

/// The physics thread. Construction loads the model and builds the PLC emulator (nothing runs yet);
/// start() opens the Modbus server (if configured up) and starts the thread; stop() (or the
/// destructor) stops the arm and the crane, closes the Modbus server and joins the thread.
class SimRunner {
 public:
  /// @throws sim::PhysicsModelError, sim::CellGeometryError, plc::PlcConfigError.
  SimRunner(CellSimConfig config, sim::CellGeometry geometry, SimOutputs& outputs, Logger log);
  ~SimRunner();
  SimRunner(const SimRunner&) = delete;
  SimRunner& operator=(const SimRunner&) = delete;

  /// The camera to feed `rate_hz` times per simulated second (optional; it must outlive the
  /// runner's thread). Before start().
  void set_camera(CameraWorker* camera, double rate_hz);
  /// A copy of the physics' compiled model for the camera's renderer. Before start().
  std::shared_ptr<const mjModel_> copy_physics_model() const { return physics_->copy_model(); }
  /// @throws crane::ModbusError when the Modbus server cannot listen (port in use).
  void start();
  /// Idempotent; leaves the devices safe.
  void stop();

  /// Queues a command for the physics thread (applied before its next step). Thread-safe.
  void submit(SimCommand command);
  /// Runs `steps` physics steps on the caller's thread, unpaced (tests, benchmark). Only while the
  /// thread is not running.
  void step_for_test(std::uint64_t steps);

  /// The Modbus server's port (0 while the link is down). Thread-safe.
  std::uint16_t plc_port() const { return plc_->port(); }
  const CellSimConfig& config() const { return config_; }
  const sim::CellGeometry& geometry() const { return geometry_; }

 private:
  struct ActiveMotion {
    std::string motion_id;
    std::uint64_t physics_id = 0;
    std::chrono::nanoseconds deadline{0};  // simulated time; zero: none
    bool stop = false;                     // a MOTION_STOP: succeeds once the arm is at rest
  };

  void run();
  void one_step(WallTime now);
  void step_and_publish(WallTime now);
  void drain_mailbox(WallTime now);
  void apply(const TwistCommand& command, WallTime now);
  void apply(const MotionCommand& command, WallTime now);
  void apply(const GripperCommand& command, WallTime now);
  void apply(const SimControlCommand& command, WallTime now);
  void apply(const ObjectMovesCommand& command, WallTime now);
  void apply(const ModelSwapCommand& command, WallTime now);
  /// Why `command` cannot be swapped in now (empty: it can), after continue_from and the moves on it.
  std::string prepare_swap(const ModelSwapCommand& command) const;
  void index_truth(std::vector<std::string> removed);
  void set_estop(bool pressed, WallTime now);
  void reset_physics(WallTime now);
  void track_motion(const sim::RobotState& robot, WallTime now);
  void end_motion(MotionPhase phase, const std::string& code, const std::string& message, WallTime now);
  void publish_due(WallTime now);
  StatusReport status_report() const;
  void make_safe();
  void update_measured_rate(std::chrono::steady_clock::time_point wall_now);

  CellSimConfig config_;
  sim::CellGeometry geometry_;
  SimOutputs& outputs_;
  Logger log_;

  // Owned by the physics thread (or the caller of step_for_test while it does not run).
  std::shared_ptr<sim::CellPhysics> physics_;  // shared: a swap hands it over in a copyable command
  PhysicsCraneAxes axes_;
  std::unique_ptr<plc::PlcEmulator> plc_;  // thread-safe itself
  sim::RealTimePacer pacer_;
  CameraWorker* camera_ = nullptr;
  std::uint64_t steps_ = 0;
  std::uint64_t overruns_ = 0;
  std::optional<TwistCommand> twist_;
  std::optional<ActiveMotion> motion_;
  bool estop_ = false;
  std::uint64_t last_robot_command_seq_ = 0;
  std::uint64_t last_gripper_command_seq_ = 0;
  bool last_gripper_published_valid_ = false;
  sim::GripperState last_gripper_published_;
  GroundTruth truth_;  // one entry per object body, made once; poses refreshed at the truth rate
  Eigen::Vector3d load_external_force_n_ = Eigen::Vector3d::Zero();
  std::uint64_t plc_every_ = 1, wrench_every_ = 1, robot_every_ = 1, gripper_every_ = 1, truth_every_ = 1,
                status_every_ = 1, camera_every_ = 0;
  // Measured real-time factor over about a second of wall time.
  std::chrono::steady_clock::time_point rate_wall_anchor_{};
  std::chrono::nanoseconds rate_sim_anchor_{0};
  double measured_rate_ = 0.0;
  std::chrono::steady_clock::time_point last_lag_log_{};
  std::chrono::steady_clock::time_point last_refusal_log_{};
  /// A swap in this step: its promise is kept once the step is done (with the step's wall time).
  std::shared_ptr<std::promise<ModelSwapResult>> swap_done_;
  std::chrono::steady_clock::time_point swap_started_{};

  mutable std::mutex mailbox_mutex_;
  std::vector<SimCommand> mailbox_;
  std::atomic<bool> stop_{false};
  std::thread thread_;
};

}  // namespace rigger::cell_sim
