#include "calibrate_camera.hpp"

#include <algorithm>
#include <ctime>
#include <stdexcept>

#include "fixed_text.hpp"

#include "rigger/cell_config/calibration_board.hpp"
#include "rigger/skill_sdk/params.hpp"

namespace rigger::skill_executor {

namespace {

constexpr double kPi = 3.14159265358979323846;

std::string utc_text(WallTime t) {
  const std::time_t seconds = std::chrono::system_clock::to_time_t(t);
  std::tm tm{};
  gmtime_r(&seconds, &tm);
  char text[32];
  std::strftime(text, sizeof text, "%Y-%m-%dT%H:%M:%SZ", &tm);
  return text;
}

}  // namespace

const skill::SkillDescription& CalibrateCameraSkill::describe() {
  static const skill::SkillDescription kDescription = [] {
    skill::SkillDescription d;
    d.name = "CalibrateCamera";
    d.kind = skill::SkillKind::kSkill;
    d.description =
        "Finds where the camera really is: the robot shows the calibration board on its tool to the camera in "
        "poses chosen about where the arm holds it (tilted about varied axes), the tracker measures the board in "
        "the camera's frame at each, and the camera's pose is solved by least squares over the pose pairs. A pose "
        "counts when the whole board is in the camera's picture and faces it within 60 deg: the poses are moved up "
        "to 20 cm toward the picture's middle for that. A pose the arm does not reach, or where the tracker does "
        "not see the board, is skipped (recorded with why) and a spare pose stands in for it. When "
        "the residual is within bounds, the camera's pose is written as a cell revision with the calibration "
        "record in the camera's attributes.calibration; else nothing changes. Start with the board in the "
        "camera's picture.";
    d.params = {
        params::object("camera", "The camera entity to calibrate.", "camera"),
        params::object("robot", "The robot carrying the calibration board (its cell entity).", "robot"),
        params::integer("poses").range(4, 24).fallback(10).doc(
            "How many board poses to measure; spares (half as many again, at least 2) stand in for poses not "
            "reached or not seen."),
        params::number("tilt_rad")
            .unit("rad")
            .range(5.0 * kPi / 180.0, 35.0 * kPi / 180.0)
            .fallback(15.0 * kPi / 180.0)
            .doc("How far each pose turns the board off facing the camera (15 deg)."),
        params::number("shift_m").unit("m").range(0.0, 0.15).fallback(0.05).doc(
            "How far each pose moves the board in its plane."),
        params::number("max_residual_m")
            .unit("m")
            .range(0.05e-3, 0.05)
            .fallback(2e-3)
            .doc("Largest accepted RMS distance between the board as seen and as the solution puts it (2 mm)."),
        params::number("max_residual_rad")
            .unit("rad")
            .range(0.01 * kPi / 180.0, 10.0 * kPi / 180.0)
            .fallback(0.5 * kPi / 180.0)
            .doc("Largest accepted RMS angle between the board as seen and as the solution puts it (0.5 deg)."),
        params::number("view_timeout_s")
            .unit("s")
            .range(0.5, 30.0)
            .fallback(6.0)
            .doc("How long each pose waits for the tracker to see the board before it is skipped."),
        params::speed_scale(0.3),
        params::text("requested_by")
            .range(0, 200)
            .fallback("")
            .doc("Who asked for the calibration (kept with the revision's who); riggerctl fills it."),
        params::timeout_s(30.0, "Each motion fails with TIMEOUT after this (the arm is stopped)."),
    };
    d.resources = {"robot", "camera"};
    d.pausable = true;
    return d;
  }();
  return kDescription;
}

CalibrateCameraSkill::CalibrateCameraSkill() {
  const auto stop = [this](SafeStopDone done) { stop_robot(done); };
  add_state({"read_cell", [this] { read_cell(); }, nothing_to_stop});
  // Paused, the arm stops where it is; resumed, the same pose is asked for again from there.
  add_state({"move", [this] { move(); }, stop, stop});
  add_state({"measure", [this] { measure(); }, nothing_to_stop});
  add_state({"return", [this] { return_to_start(); }, stop, stop});
  add_state({"solve", [this] { solve(); }, nothing_to_stop});
  add_state({"check", [this] { check(); }, nothing_to_stop});
  add_state({"apply", [this] { apply(); }, nothing_to_stop});
}

void CalibrateCameraSkill::read_cell() {
  const Devices& devices = ctx().devices();
  if (!require_devices({{devices.robot != nullptr, "robot"},
                        {devices.tracker != nullptr, "vision tracker"},
                        {devices.world_access != nullptr, "world model"}}))
    return;
  camera_id_ = params().at("camera").get<std::string>();
  const std::string robot_id = params().at("robot").get<std::string>();
  board_id_ = cell::calibration_board_id(robot_id);
  ctx().progress(0.02, "reading the running cell");
  WorldAccess* world = devices.world_access;
  const OpId id = world->running_cell(
      kWorldTimeout, guard([this, robot_id](const OpResult& r, const CellDocument& doc) {
        if (!r.ok) {
          fail(r.code == "WORLD_UNREACHABLE" ? r.code : "CELL_UNAVAILABLE",
               "the running cell: " + r.code + ": " + r.message);
          return;
        }
        running_ = doc;
        try {
          cell_ = cell::parse_cell_file(doc.cell_json, "cell revision " + std::to_string(doc.revision));
          const cell::CellEntity& camera = cell_->require(camera_id_, "CalibrateCamera");
          const cell::CellEntity& robot = cell_->require(robot_id, "CalibrateCamera");
          if (!camera.camera) throw std::runtime_error("'" + camera_id_ + "' has no camera block");
          if (!robot.calibration_board) throw std::runtime_error("'" + robot_id + "' carries no calibration_board");
          pose_world_base_ = cell_->pose_root_entity(robot_id);
          pose_tool_board_ = robot.calibration_board->pose_tool_board;
          board_size_m_ = std::max(robot.calibration_board->size_m.x(), robot.calibration_board->size_m.y());
        } catch (const std::exception& e) {
          fail("CELL_UNAVAILABLE", std::string("cell revision ") + std::to_string(doc.revision) + ": " + e.what());
          return;
        }
        read_arm();
      }));
  track([world, id] { world->cancel(id); });
}

void CalibrateCameraSkill::read_arm() {
  RobotMotion* robot = ctx().devices().robot;
  const OpId id = robot->next_state(kStateTimeout, guard([this](std::optional<RobotSnapshot> s) {
                                      if (s)
                                        plan(*s);
                                      else
                                        fail("ROBOT_STATE_STALE", "no robot state within 1 s");
                                    }));
  track([robot, id] { robot->cancel(id); });
}

void CalibrateCameraSkill::plan(const RobotSnapshot& state) {
  start_tool_ = state.tool_pose;
  calibration::PosePlanInput in;
  in.pose_base_tool_now = state.tool_pose;
  in.pose_tool_board = pose_tool_board_;
  in.pose_base_camera = pose_world_base_.inverse() * cell_->pose_root_entity(camera_id_);
  in.camera = *cell_->find(camera_id_)->camera;
  in.board_size_m = board_size_m_;
  wanted_ = params().at("poses").get<int>();
  // Spares stand in for poses the arm does not reach or the camera does not see there.
  in.count = wanted_ + std::max(2, wanted_ / 2);
  in.tilt_rad = params().at("tilt_rad").get<double>();
  in.shift_m = params().at("shift_m").get<double>();
  planned_ = calibration::plan_poses(in);
  if (static_cast<int>(planned_.size()) < kMinPoses) {
    fail("NO_POSES_IN_VIEW", std::to_string(planned_.size()) +
                                 " of the planned poses keep the board in the camera's "
                                 "picture (" +
                                 std::to_string(kMinPoses) +
                                 " needed): start with the board nearer the "
                                 "picture's centre, or lower tilt_rad and shift_m");
    return;
  }
  ctx().log()->info("CalibrateCamera: {} poses wanted, {} planned about the tool at ({:.3f}, {:.3f}, {:.3f}) m",
                    wanted_, planned_.size(), start_tool_.translation().x(), start_tool_.translation().y(),
                    start_tool_.translation().z());
  transition("move");
}

void CalibrateCameraSkill::move() {
  ctx().progress(0.05 + 0.8 * static_cast<double>(pairs_.size()) / static_cast<double>(wanted_),
                 "pose " + std::to_string(next_ + 1) + " (" + std::to_string(pairs_.size()) + " of " +
                     std::to_string(wanted_) + " seen)");
  MotionGoal goal;
  goal.kind = MotionGoal::Kind::kCartesian;
  goal.pose_frame_tool = planned_[next_];
  goal.frame = "robot";
  goal.speed_scale = params().at("speed_scale").get<double>();
  RobotMotion* robot = ctx().devices().robot;
  const OpId id =
      robot->move(goal, from_seconds(params().at("timeout_s").get<double>()), guard([this](const OpResult& result) {
                    if (result.ok) {
                      ++reached_;
                      transition("measure");
                    } else if (result.message.rfind("UNREACHABLE", 0) == 0) {
                      next_pose("unreachable");
                    } else {
                      fail(result.code, "pose " + std::to_string(next_ + 1) + ": " + result.message);
                    }
                  }));
  track([robot, id] { robot->cancel(id); });
}

void CalibrateCameraSkill::measure() {
  first_command_.reset();
  tool_now_.reset();
  RobotMotion* robot = ctx().devices().robot;
  const OpId state_id = robot->next_state(kStateTimeout, guard([this](std::optional<RobotSnapshot> s) {
                                            if (!s) {
                                              fail("ROBOT_STATE_STALE",
                                                   "no robot state within 1 s after pose " + std::to_string(next_ + 1));
                                              return;
                                            }
                                            tool_now_ = s->tool_pose;
                                            send_once();
                                          }));
  track([robot, state_id] { robot->cancel(state_id); });
  VisionTracker* tracker = ctx().devices().tracker;
  const OpId watch = tracker->watch(board_id_, guard([this](const TrackedObjectSample& s) { on_sample(s); }));
  track([tracker, watch] { tracker->cancel(watch); });
  track([this] {
    if (retry_timer_ != 0) ctx().cancel_timer(retry_timer_);
    retry_timer_ = 0;
  });
  after(from_seconds(params().at("view_timeout_s").get<double>()), [this] { next_pose("board not seen"); });
}

void CalibrateCameraSkill::send_once() {
  last_command_ = ctx().devices().tracker->command(TrackerRequest::kOnce, board_id_);
  if (!first_command_) first_command_ = last_command_;
  // Re-armed per command: a pose lost on the best-effort topic must not stall the measurement.
  if (retry_timer_ != 0) ctx().cancel_timer(retry_timer_);
  retry_timer_ = ctx().after(kRetryPeriod, guard([this] {
                               retry_timer_ = 0;
                               send_once();
                             }));
}

void CalibrateCameraSkill::on_sample(const TrackedObjectSample& s) {
  if (!first_command_ || s.stamp <= *first_command_) return;  // an image taken before the arm stood here
  if (s.tracked && s.pose.matrix().allFinite()) {
    if (s.frame != camera_id_) {
      fail("BOARD_NOT_SEEN", "the tracker measures the board in '" + s.frame + "', not in the camera '" + camera_id_ +
                                 "''s frame: it calibrates another camera");
      return;
    }
    pairs_.push_back({*tool_now_, s.pose});
    next_pose("");
    return;
  }
  // Not tracked: the tracker's answer to a TRACK_ONCE it could not end within its own wait (the board not
  // found, or found too poorly), or one image without it while it tracks continuously, which is asked again.
  if (s.stamp - *first_command_ >= kNotSeenAfter) {
    next_pose("board not seen" + (s.detail.empty() ? std::string() : ": " + s.detail));
    return;
  }
  if (s.stamp > last_command_) send_once();
}

void CalibrateCameraSkill::next_pose(const std::string& skipped_because) {
  if (!skipped_because.empty()) {
    skipped_.push_back("pose " + std::to_string(next_ + 1) + ": " + skipped_because);
    ctx().log()->info("CalibrateCamera: pose {} skipped: {}", next_ + 1, skipped_because);
  }
  ++next_;
  const bool enough = static_cast<int>(pairs_.size()) >= wanted_;
  transition(!enough && next_ < planned_.size() ? "move" : "return");
}

void CalibrateCameraSkill::return_to_start() {
  ctx().progress(0.88, "back to the start pose");
  MotionGoal goal;
  goal.kind = MotionGoal::Kind::kCartesian;
  goal.pose_frame_tool = start_tool_;
  goal.frame = "robot";
  goal.speed_scale = params().at("speed_scale").get<double>();
  RobotMotion* robot = ctx().devices().robot;
  const OpId id =
      robot->move(goal, from_seconds(params().at("timeout_s").get<double>()), guard([this](const OpResult& result) {
                    if (result.ok)
                      transition("solve");
                    else
                      fail(result.code, "back to the start pose: " + result.message);
                  }));
  track([robot, id] { robot->cancel(id); });
}

void CalibrateCameraSkill::solve() {
  const std::string skipped = skipped_.empty() ? std::string() : " (" + std::to_string(skipped_.size()) + " skipped)";
  if (reached_ < kMinPoses) {
    fail("POSES_UNREACHABLE", "the arm reached " + std::to_string(reached_) + " of " + std::to_string(next_) +
                                  " poses, " + std::to_string(kMinPoses) +
                                  " needed: start nearer the middle of the arm's reach");
    return;
  }
  if (static_cast<int>(pairs_.size()) < kMinPoses) {
    fail("BOARD_NOT_SEEN", "the camera saw the board '" + board_id_ + "' at " + std::to_string(pairs_.size()) + " of " +
                               std::to_string(reached_) + " poses reached, " + std::to_string(kMinPoses) +
                               " needed: is the board in the picture, lit, and mounted as the cell says?");
    return;
  }
  std::vector<Eigen::Isometry3d> tools;
  for (const calibration::PosePair& p : pairs_) tools.push_back(p.pose_base_tool);
  spread_deg_ = calibration::axis_spread_deg(tools);
  if (spread_deg_ < kMinAxisSpreadDeg) {
    fail("DEGENERATE_POSES", "the " + std::to_string(pairs_.size()) + " poses seen turn the board about one axis " +
                                 "only (axis spread " + fixed(spread_deg_, 1) + " deg, at least " +
                                 fixed(kMinAxisSpreadDeg, 0) + " needed): the camera's pose is not determined");
    return;
  }
  solution_ = calibration::solve(pairs_, pose_tool_board_, board_size_m_);
  pose_world_camera_ = pose_world_base_ * solution_.pose_base_camera;
  const Eigen::Isometry3d drawn = cell_->pose_root_entity(camera_id_);
  const Eigen::Isometry3d moved = drawn.inverse() * pose_world_camera_;
  summary_ = std::to_string(pairs_.size()) + " poses" + skipped + ", residual " + fixed(solution_.rms_mm, 2) +
             " mm / " + fixed(solution_.rms_deg, 3) + " deg rms (max " + fixed(solution_.max_mm, 2) + " mm / " +
             fixed(solution_.max_deg, 3) + " deg); the camera is " + fixed(moved.translation().norm() * 1e3, 2) +
             " mm / " + fixed(calibration::angle_deg(moved.linear()), 3) + " deg from where the cell had it";
  ctx().log()->info("CalibrateCamera: {}", summary_);
  const double max_mm = params().at("max_residual_m").get<double>() * 1e3;
  const double max_deg = params().at("max_residual_rad").get<double>() * 180.0 / kPi;
  if (solution_.rms_mm > max_mm || solution_.rms_deg > max_deg) {
    fail("RESIDUAL_TOO_LARGE", summary_ + ": over the bound of " + fixed(max_mm, 2) + " mm / " + fixed(max_deg, 3) +
                                   " deg rms; the cell is unchanged");
    return;
  }
  transition("check");
}

nlohmann::json CalibrateCameraSkill::revised_document() const {
  nlohmann::json doc = nlohmann::json::parse(running_.cell_json);
  const cell::CellEntity& camera = *cell_->find(camera_id_);
  const Eigen::Isometry3d world_parent =
      camera.parent.empty() ? Eigen::Isometry3d::Identity() : cell_->pose_root_entity(camera.parent);
  const Eigen::Isometry3d parent_camera = world_parent.inverse() * pose_world_camera_;
  nlohmann::json poses = nlohmann::json::array();
  for (std::size_t i = 0; i < pairs_.size(); ++i) {
    poses.push_back({{"base_tool", calibration::pose_json(pairs_[i].pose_base_tool)},
                     {"camera_board", calibration::pose_json(pairs_[i].pose_camera_board)},
                     {"residual_mm", solution_.residuals[i].mm},
                     {"residual_deg", solution_.residuals[i].deg}});
  }
  const std::string requested_by = params().at("requested_by").get<std::string>();
  const nlohmann::json record = {
      {"skill", "CalibrateCamera"},
      {"requested_by", requested_by},
      {"stamp", utc_text(std::chrono::system_clock::now())},
      {"from_revision", running_.revision},
      {"residual_rms_mm", solution_.rms_mm},
      {"residual_rms_deg", solution_.rms_deg},
      {"residual_max_mm", solution_.max_mm},
      {"residual_max_deg", solution_.max_deg},
      {"max_residual_mm", params().at("max_residual_m").get<double>() * 1e3},
      {"max_residual_deg", params().at("max_residual_rad").get<double>() * 180.0 / kPi},
      {"axis_spread_deg", spread_deg_},
      {"previous_pose", calibration::pose_json(camera.pose_parent_entity.value_or(Eigen::Isometry3d::Identity()))},
      {"board_mount", calibration::pose_json(solution_.pose_tool_board)},
      {"skipped", skipped_},
      {"poses", poses}};
  for (nlohmann::json& entity : doc.at("entities")) {
    if (entity.value("id", "") != camera_id_) continue;
    entity["pose"] = calibration::pose_json(parent_camera);
    entity["attributes"]["calibration"] = record;
  }
  return doc;
}

void CalibrateCameraSkill::check() {
  ctx().progress(0.92, "checking the revision (dry run)");
  document_ = revised_document().dump(2) + "\n";
  CellProposal proposal;
  proposal.cell_json = document_;
  proposal.dry_run = true;
  WorldAccess* world = ctx().devices().world_access;
  const OpId id = world->propose_cell(
      proposal, kWorldTimeout, guard([this](const OpResult& r, const CellProposalAnswer& answer) {
        if (!r.ok) {
          fail(r.code == "WORLD_UNREACHABLE" ? r.code : "WORLD_UPDATE_REJECTED",
               "the world model refused the camera's pose (dry run): " + r.code + ": " + r.message);
          return;
        }
        // The revision must touch the camera alone: anything else would be a change nobody asked for.
        for (const char* key : {"added", "removed"}) {
          if (!answer.changes.value(key, nlohmann::json::array()).empty()) {
            fail("WORLD_UPDATE_REJECTED",
                 std::string("the revision would have ") + key + " entities: " + answer.changes.at(key).dump());
            return;
          }
        }
        for (const char* key : {"moved", "changed"}) {
          for (const nlohmann::json& c : answer.changes.value(key, nlohmann::json::array())) {
            if (c.value("id", "") != camera_id_) {
              fail("WORLD_UPDATE_REJECTED", std::string("the revision would have ") + key + " " + c.value("id", "?"));
              return;
            }
          }
        }
        transition("apply");
      }));
  track([world, id] { world->cancel(id); });
}

void CalibrateCameraSkill::apply() {
  ctx().progress(0.96, "writing the camera's pose as a cell revision");
  CellProposal proposal;
  proposal.cell_json = document_;  // exactly what the dry run checked
  const std::string requested_by = params().at("requested_by").get<std::string>();
  proposal.who = "CalibrateCamera" + (requested_by.empty() ? std::string() : " for " + requested_by);
  proposal.comment = "camera " + camera_id_ + " calibrated: " + summary_;
  WorldAccess* world = ctx().devices().world_access;
  const OpId id =
      world->propose_cell(proposal, kWorldTimeout, guard([this](const OpResult& r, const CellProposalAnswer& answer) {
                            if (!r.ok) {
                              fail(r.code == "WORLD_UNREACHABLE" ? r.code : "WORLD_UPDATE_REJECTED",
                                   "the world model refused the camera's pose: " + r.code + ": " + r.message);
                              return;
                            }
                            succeed("camera " + camera_id_ + " calibrated, cell revision " +
                                    std::to_string(answer.revision) + ": " + summary_);
                          }));
  track([world, id] { world->cancel(id); });
}

void CalibrateCameraSkill::stop_robot(const SafeStopDone& done) {
  // Not guarded: the safe stop runs after the state was left, and its answer is what STOPPED waits for.
  ctx().devices().robot->stop(kStopTimeout, [done](const OpResult& result) { done(result.ok, result.message); });
}

}  // namespace rigger::skill_executor
