#pragma once
/// @file
/// Device primitives of the cell beyond the robot and the gripper (primitives.hpp): the crane's health
/// and external control, the vision tracker, the admittance controller, the operator's prompts and
/// the world model's features and pose updates. Interfaces, so that skill FSMs are unit-tested with
/// fakes (test/cell_fakes.hpp); the DDS implementations are in dds_cell_devices.hpp.
///
/// Every asynchronous operation ends with exactly one callback unless cancelled (cancel(id) drops
/// it; it never stops a device). Watches call back per sample until cancelled.
/// Thread safety: every call and every callback on the owner's event loop thread.

#include <chrono>
#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Geometry>
#include <nlohmann/json.hpp>

#include "rigger/skill_sdk/primitives.hpp"
#include "rigger/base/time.hpp"

namespace rigger::skill_sdk {

// ---------------------------------------------------------------------------------------------------
// Crane (rigger/crane/state, rigger/crane/control)

/// Failure code of every crane problem a skill reports: a fault, the PLC link down, an e-stop,
/// overload, no fresh rigger/crane/state, or external control not granted.
inline constexpr const char* kCraneFault = "CRANE_FAULT";

/// The crane as of one rigger/crane/state sample.
struct CraneSnapshot {
  WallTime stamp;  ///< the gateway's stamp (wall clock)
  bool link_ok = false;
  bool ready = false;
  bool enabled = false;
  bool external_control = false;
  bool moving = false;
  bool fault = false;
  bool estop = false;
  bool overload = false;
  std::uint16_t fault_code = 0;
  std::string fault_text;
};

/// Why this crane state cannot hold (or move) a load, or std::nullopt when it can: the PLC link is
/// down, the PLC is not ready, a fault (with its code and text), an e-stop or an overload.
std::optional<std::string> crane_problem(const CraneSnapshot& state);

/// The crane as a load-holding device. Use check_health() as the precondition of every skill that
/// moves the robot while the crane carries the load, and watch_health() while it does.
class CraneMonitor {
 public:
  virtual ~CraneMonitor() = default;
  /// Waits for a crane state stamped no earlier than `max_age` before the call; `done` ok when it shows
  /// a healthy crane, else kCraneFault with crane_problem()'s text, or kCraneFault "no fresh crane
  /// state" after `timeout`. A fresh enough state already received answers at once (next loop turn).
  /// A state without a PLC link does not answer: the gateway may be (re)connecting, so the check waits
  /// for the link until `timeout`, then fails saying the link is down.
  virtual OpId check_health(std::chrono::nanoseconds max_age, std::chrono::nanoseconds timeout, OpCallback done) = 0;
  /// Calls `on_problem` (kCraneFault) once: at the first crane state showing a problem, or when no
  /// crane state arrived for `max_silence`. Runs until cancel().
  virtual OpId watch_health(std::chrono::nanoseconds max_silence, OpCallback on_problem) = 0;
  /// Requests external control (CRANE_REQUEST_EXTERNAL: enable + external velocity mode) unless the
  /// crane already reports it; `done` ok once a state shows enabled and external control granted,
  /// kCraneFault after `timeout` or at once when a state shows a problem.
  virtual OpId request_external(std::chrono::nanoseconds timeout, OpCallback done) = 0;
  virtual void cancel(OpId id) = 0;
};

// ---------------------------------------------------------------------------------------------------
// Vision tracker (rigger/tracker/command, rigger/tracker/pose)

/// kOnceByModel: TRACK_ONCE_MODEL, once from the next depth image by the object's STEP model, no markers.
enum class TrackerRequest { kOnce, kContinuous, kStop, kOnceByModel };

/// One rigger/tracker/pose sample.
struct TrackedObjectSample {
  std::string object_id;
  std::string frame;  ///< frame of `pose` (the tracker's frame_id, "world" in the cell)
  WallTime stamp;     ///< the image's stamp
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();  ///< T_frame_object, m; identity when !tracked
  double quality = 0.0;                                    ///< [0, 1]; 0 when !tracked
  bool tracked = false;
  /// From the marker tracker: empty, or NOT_SEEN for a kOnce that ended without a pose (detail: the images
  /// looked at and the best quality in them). The answer to a kOnceByModel: "FOUND" or why no pose is given
  /// (NOT_FOUND, LOW_FIT, AMBIGUOUS, BAD_DEPTH, NO_VISIBLE_SURFACE, NO_MODEL, NO_DEPTH), detail in words.
  std::string status;
  std::string detail;
};

class VisionTracker {
 public:
  virtual ~VisionTracker() = default;
  /// Writes a TrackerCommand for `object_id` (the tracker's mode is global: TRACK_ONCE processes the
  /// next image, TRACK_CONTINUOUS every image, TRACK_STOP none). Returns the command's stamp: a pose of
  /// an image stamped after it was taken after the command.
  virtual WallTime command(TrackerRequest request, const std::string& object_id) = 0;
  /// Every pose sample of `object_id` from now on, until cancel().
  virtual OpId watch(const std::string& object_id, std::function<void(const TrackedObjectSample&)> on_sample) = 0;
  virtual void cancel(OpId id) = 0;
};

// ---------------------------------------------------------------------------------------------------
// Admittance controller (rigger/admittance/command, rigger/admittance/state)

enum class AdmittanceModeRequest { kOff, kRobot, kRobotAndCrane };
enum class AdmittanceReference { kNone, kJoystick, kVisualServo };
/// The wire names, for messages: "OFF", "ROBOT", "ROBOT_AND_CRANE"; "NONE", "JOYSTICK", "VISUAL_SERVO".
const char* admittance_mode_name(AdmittanceModeRequest mode);
const char* admittance_reference_name(AdmittanceReference reference);

/// One AdmittanceCommand (gains are left at the controller's configured defaults).
struct AdmittanceRequest {
  AdmittanceModeRequest mode = AdmittanceModeRequest::kOff;
  AdmittanceReference reference = AdmittanceReference::kNone;
  std::string servo_object;  ///< kVisualServo: the tracked object that moves (e.g. "load")
  std::string servo_target;  ///< kVisualServo: the tracked object it goes to (e.g. "target")
  Eigen::Isometry3d servo_goal_in_target =
      Eigen::Isometry3d::Identity();  ///< the object's goal pose in the target frame
  /// The robot law's stiffness per axis of its frame (x y z N/m, rx ry rz N m/rad): a spring that pulls the
  /// tool back onto the reference's path. Empty: admittance_control's configured stiffness.
  std::vector<double> stiffness;
};

/// One rigger/admittance/state sample.
struct AdmittanceSnapshot {
  WallTime stamp;
  AdmittanceModeRequest mode = AdmittanceModeRequest::kOff;
  AdmittanceReference reference = AdmittanceReference::kNone;
  bool fault = false;
  std::string fault_code;
  std::string fault_text;
  double robot_speed_mps = 0.0;    ///< |linear robot twist|
  double robot_speed_radps = 0.0;  ///< |angular robot twist|
  double crane_speed_mps = 0.0;    ///< |crane velocity|
  bool servo_converged = false;
  double servo_error_m = 0.0;
  double servo_error_rad = 0.0;
  std::uint64_t last_command_seq = 0;
};

/// Outputs below this count as at rest when confirming OFF (m/s and rad/s).
inline constexpr double kAdmittanceRestSpeed = 1e-3;

class AdmittanceController {
 public:
  virtual ~AdmittanceController() = default;
  /// Sends the command (source = the executor id; the controller goes OFF when that process is lost).
  /// `done` ok once a state reports this command applied (last_command_seq ≥ its seq with the requested
  /// mode and reference; for OFF also robot and crane outputs at rest); ADMITTANCE_REFUSED when a state
  /// acknowledges the seq with another mode; TIMEOUT after `timeout`.
  virtual OpId command(const AdmittanceRequest& request, std::chrono::nanoseconds timeout, OpCallback done) = 0;
  /// Every admittance state sample from now on, until cancel().
  virtual OpId watch(std::function<void(const AdmittanceSnapshot&)> on_state) = 0;
  virtual void cancel(OpId id) = 0;
};

// ---------------------------------------------------------------------------------------------------
// Operator (rigger/operator/prompt, rigger/operator/response)

struct OperatorPromptSpec {
  std::string kind;  ///< e.g. "screw", "confirm"
  std::string title;
  std::string text;
  std::vector<std::string> options;  ///< the answers the operator may give, e.g. {"done","failed","abort"}
  nlohmann::json details = nlohmann::json::object();  ///< structured content (details_json)
  double timeout_s = 0.0;                             ///< shown to the operator; the wait's own timeout is ask()'s
};

class OperatorPanel {
 public:
  virtual ~OperatorPanel() = default;
  /// Publishes a new prompt (active, a fresh prompt_id) and waits for a response to it whose answer is
  /// one of `spec.options` (others are logged and ignored); `done(answer)`, or std::nullopt after
  /// `timeout`. The prompt stays published until withdraw(id) (also after done). Returns the id.
  virtual OpId ask(const OperatorPromptSpec& spec, std::chrono::nanoseconds timeout,
                   std::function<void(std::optional<std::string> answer)> done) = 0;
  /// Withdraws the prompt of `id` (active=false) and forgets its wait; idempotent.
  virtual void withdraw(OpId id) = 0;
};

// ---------------------------------------------------------------------------------------------------
// World model (features, pose updates, cell revisions)

/// A revision of the cell as the world model keeps it (rigger/world/cell_request CELL_SHOW).
struct CellDocument {
  std::uint64_t revision = 0;
  std::string cell_json;  ///< the whole cell document
};

/// A revision proposed to the world model (rigger/world/cell_request CELL_APPLY).
struct CellProposal {
  std::string cell_json;  ///< the whole proposed document
  std::string who;        ///< kept in the revision's history (at most 256 bytes)
  std::string comment;    ///< why, kept in the history (at most 4096 bytes)
  bool dry_run = false;   ///< validate and diff only; nothing changes
};

/// The world model's answer to an accepted proposal.
struct CellProposalAnswer {
  std::uint64_t revision = 0;                         ///< the running revision after it (dry run: unchanged)
  nlohmann::json changes = nlohmann::json::object();  ///< what changed, as rigger/world/cell's changes_json
};

class WorldAccess {
 public:
  virtual ~WorldAccess() = default;
  /// The CAD features of `entity` (the cell configuration's features format: "screw_holes",
  /// "insertion", …); a failure carries the world model's code (UNKNOWN_ENTITY, WORLD_UNREACHABLE…).
  virtual OpId features(const std::string& entity, std::chrono::nanoseconds timeout,
                        std::function<void(const OpResult&, const nlohmann::json& features)> done) = 0;
  /// Proposes pose, quality and localized=true of `entity` (T_parent_entity in `parent_frame`, observed at
  /// `stamp`); ok once the world model accepted it, else its rejection code or WORLD_UNREACHABLE.
  virtual OpId update_pose(const std::string& entity, const std::string& parent_frame, const Eigen::Isometry3d& pose,
                           WallTime stamp, double quality, std::chrono::nanoseconds timeout, OpCallback done) = 0;
  /// Says that `entity` is no longer localized (moved where no sensor saw it; its pose is kept, marked
  /// unknown); ok once the world model accepted it.
  virtual OpId mark_unlocalized(const std::string& entity, WallTime stamp, std::chrono::nanoseconds timeout,
                                OpCallback done) = 0;
  /// The running revision of the cell (CELL_SHOW); a failure carries the world model's code, or
  /// WORLD_UNREACHABLE when it did not answer within `timeout`.
  virtual OpId running_cell(std::chrono::nanoseconds timeout,
                            std::function<void(const OpResult&, const CellDocument&)> done) = 0;
  /// Proposes a revision (CELL_APPLY, checked and applied like `riggerctl cell apply`); ok once the world
  /// model accepted it (a dry run: would accept it), else its code (INVALID, HELD_BY_TASK, UNCHANGED, ...)
  /// and message, or WORLD_UNREACHABLE after `timeout`. Cell_sim and the other readers follow an accepted
  /// revision on their own, and may refuse it (their service state says so).
  virtual OpId propose_cell(const CellProposal& proposal, std::chrono::nanoseconds timeout,
                            std::function<void(const OpResult&, const CellProposalAnswer&)> done) = 0;
  virtual void cancel(OpId id) = 0;
};

}  // namespace rigger::skill_sdk
