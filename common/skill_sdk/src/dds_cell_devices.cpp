#include "dds_cell_devices.hpp"

#include <algorithm>

#include "rigger/base/text.hpp"
#include "rigger/dds/conversions.hpp"
#include "rigger/dds/qos.hpp"
#include "rigger/operator_protocol/prompt.hpp"
#include "rigger/protocol/admittance.hpp"
#include "rigger/protocol/crane.hpp"
#include "rigger/protocol/operator.hpp"
#include "rigger/protocol/vision.hpp"

namespace rigger::skill_sdk {

namespace {

std::chrono::milliseconds to_ms(std::chrono::nanoseconds d) {
  return std::max(std::chrono::milliseconds(1), std::chrono::duration_cast<std::chrono::milliseconds>(d));
}

rigger_admittance_AdmittanceMode to_wire(AdmittanceModeRequest m) {
  switch (m) {
    case AdmittanceModeRequest::kOff:
      return rigger_admittance_ADMITTANCE_OFF;
    case AdmittanceModeRequest::kRobot:
      return rigger_admittance_ADMITTANCE_ROBOT;
    case AdmittanceModeRequest::kRobotAndCrane:
      return rigger_admittance_ADMITTANCE_ROBOT_AND_CRANE;
  }
  return rigger_admittance_ADMITTANCE_OFF;
}

rigger_admittance_ReferenceSource to_wire(AdmittanceReference r) {
  switch (r) {
    case AdmittanceReference::kNone:
      return rigger_admittance_REFERENCE_NONE;
    case AdmittanceReference::kJoystick:
      return rigger_admittance_REFERENCE_JOYSTICK;
    case AdmittanceReference::kVisualServo:
      return rigger_admittance_REFERENCE_VISUAL_SERVO;
  }
  return rigger_admittance_REFERENCE_NONE;
}

}  // namespace

const char* admittance_mode_name(AdmittanceModeRequest mode) {
  switch (mode) {
    case AdmittanceModeRequest::kOff:
      return "OFF";
    case AdmittanceModeRequest::kRobot:
      return "ROBOT";
    case AdmittanceModeRequest::kRobotAndCrane:
      return "ROBOT_AND_CRANE";
  }
  return "?";
}

const char* admittance_reference_name(AdmittanceReference reference) {
  switch (reference) {
    case AdmittanceReference::kNone:
      return "NONE";
    case AdmittanceReference::kJoystick:
      return "JOYSTICK";
    case AdmittanceReference::kVisualServo:
      return "VISUAL_SERVO";
  }
  return "?";
}

// ---------------------------------------------------------------------------------------------------

std::optional<std::string> crane_problem(const CraneSnapshot& s) {
  if (!s.link_ok) return std::string("the crane gateway has no link to the PLC");
  std::string problems;
  const auto add = [&problems](const std::string& p) { problems += (problems.empty() ? "" : ", ") + p; };
  if (s.fault) {
    add("fault " + std::to_string(s.fault_code) + (s.fault_text.empty() ? "" : " (" + s.fault_text + ")"));
  }
  if (s.estop) add("e-stop latched");
  if (s.overload) add("overload");
  if (!s.ready && problems.empty()) add("the PLC is not ready");
  if (problems.empty()) return std::nullopt;
  return "crane: " + problems;
}

CraneSnapshot to_snapshot(const rigger_crane_CraneState& s) {
  CraneSnapshot out;
  out.stamp = dds::to_domain(s.header.stamp);
  out.link_ok = s.link_ok;
  out.ready = s.ready;
  out.enabled = s.enabled;
  out.external_control = s.external_control;
  out.moving = s.moving;
  out.fault = s.fault;
  out.estop = s.estop;
  out.overload = s.overload;
  out.fault_code = s.fault_code;
  out.fault_text = dds::to_string(s.fault_text);
  return out;
}

DdsCraneMonitor::DdsCraneMonitor(const dds::Participant& participant, dds::EventLoop& loop, Logger log,
                                 std::string source)
    : DdsProxy(loop, std::move(log), std::move(source)),
      control_(participant, protocol::crane::kControl),
      state_(participant, loop, protocol::crane::kState,
             [](const rigger_crane_CraneState& s) { return to_snapshot(s); }),
      pending_(loop),
      watches_(loop) {
  state_.subscribe([this](const CraneSnapshot& s) { on_state(s); });
}

OpId DdsCraneMonitor::check_health(std::chrono::nanoseconds max_age, std::chrono::nanoseconds timeout,
                                   OpCallback done) {
  const OpId id = next_op();
  Pending p;
  p.since = std::chrono::system_clock::now() - std::chrono::duration_cast<std::chrono::system_clock::duration>(max_age);
  pending_.start(id, std::move(p), std::move(done), timeout, [this, timeout](OpId op) {
    const std::string seconds = number_text(to_seconds(timeout));
    const std::string link_down = pending_.find(op)->link_down;
    pending_.finish(op, OpResult::failure(kCraneFault, link_down.empty() ? "no fresh rigger/crane/state within " +
                                                                               seconds + " s (crane gateway down?)"
                                                                         : link_down + " (for " + seconds + " s)"));
  });
  if (state_.latest())
    loop_.post([this, id] {
      if (state_.latest()) evaluate(id, *state_.latest());
    });
  return id;
}

OpId DdsCraneMonitor::request_external(std::chrono::nanoseconds timeout, OpCallback done) {
  const OpId id = next_op();
  Pending p;
  p.external = true;
  pending_.start(id, std::move(p), std::move(done), timeout, [this, timeout](OpId op) {
    pending_.finish(op, OpResult::failure(kCraneFault, "the crane did not grant external control within " +
                                                           number_text(to_seconds(timeout)) + " s"));
  });
  const auto& latest = state_.latest();
  if (latest && latest->enabled && latest->external_control && !crane_problem(*latest)) {
    loop_.post([this, id] {
      if (state_.latest()) evaluate(id, *state_.latest());
    });
    return id;
  }
  rigger_crane_CraneControl c{};
  c.header.stamp = dds::wire_now();
  c.seq = next_seq();
  c.kind = rigger_crane_CRANE_REQUEST_EXTERNAL;
  c.source = dds::wire_string(source_);
  write_command(control_, c, "crane control");
  log_->info("crane external control requested seq={}", c.seq);
  return id;
}

OpId DdsCraneMonitor::watch_health(std::chrono::nanoseconds max_silence, OpCallback on_problem) {
  const OpId id = next_op();
  watches_.start(id, max_silence, std::move(on_problem), max_silence, silence(max_silence));
  // A state received before the watch began that shows a problem counts at once.
  if (state_.latest() && crane_problem(*state_.latest())) {
    loop_.post([this, id] {
      if (state_.latest()) {
        if (auto problem = crane_problem(*state_.latest()))
          watches_.finish(id, OpResult::failure(kCraneFault, *problem));
      }
    });
  }
  return id;
}

void DdsCraneMonitor::cancel(OpId id) {
  pending_.cancel(id);
  watches_.cancel(id);
}

PendingOps<std::chrono::nanoseconds>::OnDeadline DdsCraneMonitor::silence(std::chrono::nanoseconds max_silence) {
  return [this, max_silence](OpId watch) {
    watches_.finish(watch,
                    OpResult::failure(kCraneFault, "no rigger/crane/state for " + number_text(to_seconds(max_silence)) +
                                                       " s (crane gateway down?)"));
  };
}

void DdsCraneMonitor::on_state(const CraneSnapshot& s) {
  for (OpId id : pending_.ids()) evaluate(id, s);
  const auto problem = crane_problem(s);
  for (OpId id : watches_.ids()) {
    const std::chrono::nanoseconds* max_silence = watches_.find(id);
    if (max_silence == nullptr) continue;
    if (problem)
      watches_.finish(id, OpResult::failure(kCraneFault, *problem));
    else
      watches_.rearm(id, *max_silence, silence(*max_silence));
  }
}

void DdsCraneMonitor::evaluate(OpId id, const CraneSnapshot& s) {
  Pending* p = pending_.find(id);
  if (p == nullptr) return;
  const auto problem = crane_problem(s);
  if (p->external) {
    if (problem)
      pending_.finish(id, OpResult::failure(kCraneFault, *problem));
    else if (s.enabled && s.external_control)
      pending_.finish(id, OpResult::success("external control granted"));
    return;
  }
  if (s.stamp < p->since) return;  // too old: wait for a fresh one
  if (!s.link_ok) {  // the gateway is (re)connecting to the PLC: wait for the link, up to the timeout
    p->link_down = *problem;
    return;
  }
  if (problem)
    pending_.finish(id, OpResult::failure(kCraneFault, *problem));
  else
    pending_.finish(id, OpResult::success("crane healthy"));
}

// ---------------------------------------------------------------------------------------------------

TrackedObjectSample to_sample(const rigger_vision_TrackedPose& s) {
  TrackedObjectSample out;
  out.object_id = dds::to_string(s.object_id);
  out.frame = dds::to_string(s.header.frame_id);
  out.stamp = dds::to_domain(s.header.stamp);
  out.tracked = s.tracked;
  out.quality = s.quality;
  if (s.tracked) out.pose = dds::to_domain(s.pose.pose);
  out.status = dds::to_string(s.status);
  out.detail = dds::to_string(s.detail);
  return out;
}

DdsVisionTracker::DdsVisionTracker(const dds::Participant& participant, dds::EventLoop& loop, Logger log,
                                   std::string source)
    : DdsProxy(loop, std::move(log), std::move(source)),
      commands_(participant, protocol::vision::kTrackerCommand),
      poses_(participant, loop, protocol::vision::kTrackerPose,
             [](const rigger_vision_TrackedPose& s) { return to_sample(s); }) {}

WallTime DdsVisionTracker::command(TrackerRequest request, const std::string& object_id) {
  const WallTime now = std::chrono::system_clock::now();
  rigger_vision_TrackerCommand c{};
  c.header.stamp = dds::to_wire(now);
  c.seq = next_seq();
  c.object_id = dds::wire_string(object_id);
  c.kind = request == TrackerRequest::kOnce          ? rigger_vision_TRACK_ONCE
           : request == TrackerRequest::kContinuous  ? rigger_vision_TRACK_CONTINUOUS
           : request == TrackerRequest::kOnceByModel ? rigger_vision_TRACK_ONCE_MODEL
                                                     : rigger_vision_TRACK_STOP;
  c.source = dds::wire_string(source_);
  write_command(commands_, c, "tracker command");
  log_->debug("tracker command seq={} object={} kind={}", c.seq, object_id, static_cast<int>(c.kind));
  return now;
}

OpId DdsVisionTracker::watch(const std::string& object_id, std::function<void(const TrackedObjectSample&)> on_sample) {
  return poses_.subscribe([object_id, on_sample = std::move(on_sample)](const TrackedObjectSample& s) {
    if (s.object_id == object_id) on_sample(s);
  });
}

// ---------------------------------------------------------------------------------------------------

AdmittanceSnapshot to_snapshot(const rigger_admittance_AdmittanceState& s) {
  AdmittanceSnapshot out;
  out.stamp = dds::to_domain(s.header.stamp);
  out.mode = s.mode == rigger_admittance_ADMITTANCE_ROBOT             ? AdmittanceModeRequest::kRobot
             : s.mode == rigger_admittance_ADMITTANCE_ROBOT_AND_CRANE ? AdmittanceModeRequest::kRobotAndCrane
                                                                      : AdmittanceModeRequest::kOff;
  out.reference = s.reference == rigger_admittance_REFERENCE_JOYSTICK       ? AdmittanceReference::kJoystick
                  : s.reference == rigger_admittance_REFERENCE_VISUAL_SERVO ? AdmittanceReference::kVisualServo
                                                                            : AdmittanceReference::kNone;
  out.fault = s.fault;
  out.fault_code = dds::to_string(s.fault_code);
  out.fault_text = dds::to_string(s.fault_text);
  const dds::Vector6d twist = dds::to_domain(s.robot_twist);
  out.robot_speed_mps = twist.head<3>().norm();
  out.robot_speed_radps = twist.tail<3>().norm();
  out.crane_speed_mps = dds::to_domain(s.crane_velocity).norm();
  out.servo_converged = s.servo_converged;
  out.servo_error_m = s.servo_error_m;
  out.servo_error_rad = s.servo_error_rad;
  out.last_command_seq = s.last_command_seq;
  return out;
}

DdsAdmittanceController::DdsAdmittanceController(const dds::Participant& participant, dds::EventLoop& loop, Logger log,
                                                 std::string source)
    : DdsProxy(loop, std::move(log), std::move(source)),
      commands_(participant, protocol::admittance::kCommand),
      state_(participant, loop, protocol::admittance::kState,
             [](const rigger_admittance_AdmittanceState& s) { return to_snapshot(s); }),
      pending_(loop) {
  state_.subscribe([this](const AdmittanceSnapshot& s) { on_state(s); });
}

OpId DdsAdmittanceController::command(const AdmittanceRequest& request, std::chrono::nanoseconds timeout,
                                      OpCallback done) {
  const OpId id = next_op();
  const std::uint64_t seq = next_seq();
  rigger_admittance_AdmittanceCommand c{};
  c.header.stamp = dds::wire_now();
  c.seq = seq;
  c.mode = to_wire(request.mode);
  c.reference = to_wire(request.reference);
  c.servo_object = dds::wire_string(request.servo_object);
  c.servo_target = dds::wire_string(request.servo_target);
  c.servo_goal_in_target = dds::to_wire(request.servo_goal_in_target);
  c.source = dds::wire_string(source_);
  std::vector<double> stiffness = request.stiffness;
  dds::wire_sequence(c.stiffness, stiffness);
  pending_.start(
      id, Pending{seq, request}, std::move(done), timeout, [this, seq, timeout, mode = request.mode](OpId op) {
        pending_.finish(
            op, OpResult::failure("TIMEOUT", "admittance_control did not confirm command seq " + std::to_string(seq) +
                                                 " (mode " + admittance_mode_name(mode) + ") within " +
                                                 number_text(to_seconds(timeout)) + " s"));
      });
  write_command(commands_, c, "admittance command");
  log_->info("admittance command seq={} mode={}", seq, admittance_mode_name(request.mode));
  return id;
}

void DdsAdmittanceController::on_state(const AdmittanceSnapshot& s) {
  std::vector<std::pair<OpId, OpResult>> results;
  for (OpId id : pending_.ids()) {
    const Pending& p = *pending_.find(id);
    if (s.last_command_seq < p.seq) continue;
    const bool mode_ok = s.mode == p.request.mode;
    const bool reference_ok = p.request.mode == AdmittanceModeRequest::kOff || s.reference == p.request.reference;
    if (mode_ok && reference_ok) {
      if (p.request.mode == AdmittanceModeRequest::kOff &&
          (s.robot_speed_mps > kAdmittanceRestSpeed || s.robot_speed_radps > kAdmittanceRestSpeed ||
           s.crane_speed_mps > kAdmittanceRestSpeed)) {
        continue;  // OFF, still ramping down
      }
      results.emplace_back(id, OpResult::success(std::string("admittance ") + admittance_mode_name(s.mode)));
    } else {
      const bool ours = s.last_command_seq == p.seq;
      results.emplace_back(
          id, OpResult::failure(ours ? "ADMITTANCE_REFUSED" : "ADMITTANCE_PREEMPTED",
                                std::string("admittance_control reports mode ") + admittance_mode_name(s.mode) +
                                    " after " + (ours ? "our" : "a newer") + " command (requested " +
                                    admittance_mode_name(p.request.mode) + ")" +
                                    (s.fault_code.empty() ? "" : "; fault " + s.fault_code)));
    }
  }
  for (const auto& [id, r] : results) pending_.finish(id, r);
}

OpId DdsAdmittanceController::watch(std::function<void(const AdmittanceSnapshot&)> on_state) {
  const OpId id = next_op();
  watches_[id] = state_.subscribe(std::move(on_state));
  return id;
}

void DdsAdmittanceController::cancel(OpId id) {
  auto w = watches_.find(id);
  if (w != watches_.end()) {
    state_.unsubscribe(w->second);
    watches_.erase(w);
    return;
  }
  pending_.cancel(id);
}

// ---------------------------------------------------------------------------------------------------

DdsOperatorPanel::DdsOperatorPanel(const dds::Participant& participant, dds::EventLoop& loop, Logger log,
                                   std::string source)
    : DdsProxy(loop, std::move(log), std::move(source)),
      prompts_(participant, protocol::operator_ui::kPrompt),
      responses_(participant, protocol::operator_ui::kResponse) {
  loop_.on_data(responses_, [this] { on_responses(); });
}

DdsOperatorPanel::~DdsOperatorPanel() {
  for (auto& [id, prompt] : open_) {
    loop_.cancel(prompt.timer);
    write(prompt, false);
  }
}

OpId DdsOperatorPanel::ask(const OperatorPromptSpec& spec, std::chrono::nanoseconds timeout,
                           std::function<void(std::optional<std::string>)> done) {
  const OpId id = next_op();
  Prompt prompt{source_ + "-" + std::to_string(next_seq()), spec, std::move(done), 0};
  prompt.timer = loop_.after(timeout, [this, id] {
    auto it = open_.find(id);
    if (it == open_.end() || !it->second.done) return;
    it->second.timer = 0;
    auto cb = std::move(it->second.done);
    it->second.done = nullptr;
    cb(std::nullopt);
  });
  write(prompt, true);
  log_->info("operator prompt {} kind={} title=\"{}\"", prompt.prompt_id, spec.kind, spec.title);
  open_.emplace(id, std::move(prompt));
  return id;
}

void DdsOperatorPanel::withdraw(OpId id) {
  auto it = open_.find(id);
  if (it == open_.end()) return;
  if (it->second.timer != 0) loop_.cancel(it->second.timer);
  write(it->second, false);
  log_->info("operator prompt {} withdrawn", it->second.prompt_id);
  open_.erase(it);
}

std::string DdsOperatorPanel::prompt_id(OpId id) const {
  auto it = open_.find(id);
  return it == open_.end() ? std::string() : it->second.prompt_id;
}

void DdsOperatorPanel::write(const Prompt& prompt, bool active) {
  operator_protocol::Prompt p;
  p.prompt_id = prompt.prompt_id;
  p.node_id = source_;
  p.kind = prompt.spec.kind;
  p.title = prompt.spec.title;
  p.text = prompt.spec.text;
  p.options = prompt.spec.options;
  p.details_json = prompt.spec.details.dump();
  p.timeout_s = prompt.spec.timeout_s;
  p.active = active;
  if (operator_protocol::write_prompt(prompts_, p) != DDS_RETCODE_OK)
    log_->warn("operator prompt write failed prompt_id={}", prompt.prompt_id);
}

void DdsOperatorPanel::on_responses() {
  std::vector<std::pair<std::function<void(std::optional<std::string>)>, std::string>> answered;
  responses_.take([&](const rigger_operator_ui_OperatorResponse& wire, const dds_sample_info_t&) {
    const operator_protocol::Response r = operator_protocol::from_wire(wire);
    const std::string& prompt_id = r.prompt_id;
    const std::string& answer = r.answer;
    for (auto& [id, prompt] : open_) {
      if (prompt.prompt_id != prompt_id || !prompt.done) continue;
      const auto& options = prompt.spec.options;
      if (std::find(options.begin(), options.end(), answer) == options.end()) {
        log_->warn("operator response to {} ignored: \"{}\" is not one of the prompt's options", prompt_id, answer);
        continue;
      }
      log_->info("operator response to {}: {} (operator {})", prompt_id, answer, r.operator_id);
      if (prompt.timer != 0) loop_.cancel(prompt.timer);
      prompt.timer = 0;
      answered.emplace_back(std::move(prompt.done), answer);
      prompt.done = nullptr;
    }
  });
  for (auto& [cb, answer] : answered) cb(answer);
}

// ---------------------------------------------------------------------------------------------------

namespace {

/// An update's answer as an OpResult: ok with the world model's code, or its rejection code.
world_client::WorldClient::Callback update_answer(OpCallback done) {
  return [done = std::move(done)](const world_client::Reply& reply) {
    if (reply.ok)
      done(OpResult::success(reply.code));
    else
      done(OpResult::failure(reply.code.empty() ? world_client::kUnreachable : reply.code, reply.message));
  };
}

}  // namespace

OpId DdsWorldAccess::features(const std::string& entity, std::chrono::nanoseconds timeout,
                              std::function<void(const OpResult&, const nlohmann::json&)> done) {
  return client_.features(entity, to_ms(timeout), [done = std::move(done)](const world_client::Reply& reply) {
    if (!reply.ok) {
      done(OpResult::failure(reply.code.empty() ? world_client::kUnreachable : reply.code, reply.message),
           nlohmann::json::object());
      return;
    }
    done(OpResult::success(), reply.result);
  });
}

OpId DdsWorldAccess::update_pose(const std::string& entity, const std::string& parent_frame,
                                 const Eigen::Isometry3d& pose, WallTime stamp, double quality,
                                 std::chrono::nanoseconds timeout, OpCallback done) {
  return client_.update_pose(entity, parent_frame, pose, stamp, quality, true, to_ms(timeout),
                             update_answer(std::move(done)));
}

OpId DdsWorldAccess::mark_unlocalized(const std::string& entity, WallTime stamp, std::chrono::nanoseconds timeout,
                                      OpCallback done) {
  return client_.set_localized(entity, false, stamp, to_ms(timeout), update_answer(std::move(done)));
}

}  // namespace rigger::skill_sdk
