#include "vision_tracker_node.hpp"

#include <filesystem>

#include <fmt/format.h>

#include "rigger/base/install.hpp"
#include "rigger/cell_config/calibration_board.hpp"
#include "rigger/dds/conversions.hpp"
#include "rigger/dds/sequences.hpp"
#include "rigger/protocol/robot.hpp"
#include "rigger/protocol/vision.hpp"
#include "rigger/protocol/world.hpp"

namespace rigger::vision {

namespace {

cell::CellFile load_cell(const VisionTrackerSettings& settings, const Config& config) {
  try {
    return cell::load_cell_file(settings.cell_file);
  } catch (const std::exception& e) {
    throw ConfigError(config.file(), config.pointer() + "/cell_file", e.what());
  }
}

Tracker make_tracker(const cell::CellFile& cell_file, const VisionTrackerSettings& settings, const Config& config) {
  try {
    TrackerConfig tracker_config = tracker_config_from_cell(cell_file, settings.camera_id);
    tracker_config.lost_after = settings.lost_after;
    return Tracker(std::move(tracker_config));
  } catch (const std::exception& e) {
    throw ConfigError(config.file(), config.pointer() + "/cell_file", e.what());
  }
}

std::vector<std::string> object_ids(const TrackerConfig& config) {
  std::vector<std::string> ids;
  for (const ObjectLayout& object : config.objects) ids.push_back(object.object_id);
  return ids;
}

const char* to_string(FrameStatus status) {
  switch (status) {
    case FrameStatus::kOk: return "ok";
    case FrameStatus::kEmptyImage: return "empty image";
    case FrameStatus::kWrongEncoding: return "not mono8";
    case FrameStatus::kWrongSize: return "not the configured camera's size";
    case FrameStatus::kOutOfOrder: return "stamp not after the previous image's";
  }
  return "unknown";
}

}  // namespace

const SettingsTable<VisionTrackerSettings>& vision_tracker_settings() {
  using S = VisionTrackerSettings;
  static const SettingsTable<S> table{
      setting<S>("frame_id", "world", &S::frame_id, "frame of the published poses"),
      path_setting<S>("cell_file", kDefaultCellFile, &S::cell_file,
                      "the cell file (the camera and the objects' layouts): relative to this file, then to the "
                      "data folder"),
      setting<S>("camera_id", "camera", &S::camera_id, "the cell entity holding the camera block"),
      setting<S>("lost_after_s", 0.5, {0.01, 10.0}, &S::lost_after, "the tracker's lost-tracking age"),
      setting<S>("once_min_quality", 0.5, {0.0, 1.0}, &S::once_min_quality,
                 "the quality a pose needs to end a TRACK_ONCE"),
      setting<S>("once_timeout_s", 2.0, {0.05, 60.0}, &S::once_timeout,
                 "when an unfinished TRACK_ONCE gives up (publishing tracked=false)"),
      choice<S>("start_mode", false, {{"idle", false}, {"continuous", true}}, &S::continuous,
                "what is tracked at start, for every object: nothing, or every image"),
  };
  return table;
}

VisionTrackerNode::VisionTrackerNode(service::ServiceContext& ctx, const VisionTrackerSettings& settings)
    : VisionTrackerNode(ctx, settings, load_cell(settings, ctx.config)) {}

VisionTrackerNode::VisionTrackerNode(service::ServiceContext& ctx, const VisionTrackerSettings& settings,
                                     const cell::CellFile& cell_file)
    : ctx_(ctx),
      frame_id_(settings.frame_id),
      camera_id_(settings.camera_id),
      lost_after_(settings.lost_after),
      tracker_(make_tracker(cell_file, settings, ctx.config)),
      schedule_(object_ids(tracker_.config()), settings.once_min_quality),
      once_timeout_(settings.once_timeout),
      once_min_quality_(settings.once_min_quality),
      images_(ctx.participant, protocol::vision::kCameraImage),
      depth_(ctx.participant, protocol::vision::kCameraDepth),
      entities_(ctx.participant, protocol::world::kEntity),
      robot_states_(ctx.participant, protocol::robot::kState),
      commands_(ctx.participant, protocol::vision::kTrackerCommand),
      poses_(ctx.participant, protocol::vision::kTrackerPose),
      model_tracker_([this](const std::string& id, Stamp stamp, const ModelLocalization& result) {
        ctx_.loop.post([this, id, stamp, result] {
          if (!result.found()) {
            ctx_.log->info("tracked by model object={} status={} elapsed_ms={} detail=\"{}\"", id, result.status,
                           std::chrono::duration_cast<std::chrono::milliseconds>(result.result.elapsed).count(),
                           result.detail);
          }
          publish_model(id, stamp, result);
        });
      }, [this](const ModelTrackerFigures& f) {
        ctx_.log->info(
            "model tracking over {:.1f} s: {} objects, {} depth images searched, {} skipped, {} searches refused, "
            "lowest model support found {:.2f}; per image {:.0f} ms (max {:.0f} ms), CPU {:.0f} ms; the search "
            "thread used {:.0f} % of a core",
            std::chrono::duration<double>(f.period).count(), f.objects, f.frames, f.skipped, f.refused,
            f.lowest_model_support, f.frame_ms_p50, f.frame_ms_max, f.cpu_ms_p50, f.busy_share * 100.0);
      }),
      follower_(ctx.participant, ctx.loop, ctx.log, settings.cell_file,
                [this](const cell_follower::FollowedRevision& revision) { return on_revision(revision); },
                &ctx.announcer) {
  const bool continuous = settings.continuous;
  if (continuous) schedule_.track_continuous("");
  model_localizer_.set_cell(cell_file, cell::cell_model_folder(settings.cell_file));
  cell_ = cell_file;
  ctx.loop.on_data(images_, [this] { on_image(); });
  ctx.loop.on_data(depth_, [this] { on_depth(); });
  ctx.loop.on_data(entities_, [this] { on_entities(); });
  ctx.loop.on_data(robot_states_, [this] { on_robot_state(); });
  ctx.loop.on_data(commands_, [this] { on_command(); });
  ctx.log->info("tracking {} objects, mode {}", tracker_.config().objects.size(), continuous ? "continuous" : "idle");
}

cell_follower::Outcome VisionTrackerNode::on_revision(const cell_follower::FollowedRevision& revision) {
  TrackerConfig config;
  try {
    config = tracker_config_from_cell(revision.cell, camera_id_);
    config.lost_after = lost_after_;
    validate(config);
  } catch (const std::exception& e) {
    return cell_follower::Outcome::refuse(e.what());
  }
  model_localizer_.set_cell(revision.cell, revision.model_dir);  // models may change with the view unchanged
  cell_ = revision.cell;
  if (same_view(config, tracker_.config())) return cell_follower::Outcome::take();
  const std::vector<std::string> ids = object_ids(config);
  tracker_ = Tracker(std::move(config));
  for (const std::string& id : schedule_.set_objects(ids)) {
    ObjectTrack lost;  // its TRACK_ONCE is answered: the object is gone
    lost.object_id = id;
    publish(lost, std::chrono::system_clock::now());
  }
  ctx_.log->info("cell revision {}: the camera or the marker layouts changed; tracking {} objects afresh",
                 revision.revision, ids.size());
  return cell_follower::Outcome::take();
}

void VisionTrackerNode::on_command() {
  commands_.take([this](const rigger_vision_TrackerCommand& cmd, const dds_sample_info_t&) {
    const bool was_active = schedule_.any_active();
    if (!apply(cmd)) {
      ++commands_dropped_;
      return;
    }
    ++commands_applied_;
    // Tracks (regions of interest, filter state) from before an idle spell are stale: start afresh.
    if (!was_active && schedule_.any_active()) tracker_.reset();
    ctx_.log->info("command seq={} source={} kind={} object={}", cmd.seq, dds::to_string(cmd.source),
                   static_cast<int>(cmd.kind), dds::to_string(cmd.object_id));
  });
}

bool VisionTrackerNode::apply(const rigger_vision_TrackerCommand& cmd) {
  const std::string object_id = dds::to_string(cmd.object_id);
  bool known = false;
  switch (cmd.kind) {
    case rigger_vision_TRACK_ONCE: {
      // Fresh means from an image taken after the command was sent (its stamp), as the sender checks.
      const Stamp sent = dds::to_domain(cmd.header.stamp);
      const Stamp fresh_after = sent > Stamp{} ? sent : std::chrono::system_clock::now();
      known = schedule_.track_once(object_id, fresh_after, dds::EventLoop::Clock::now() + once_timeout_);
      if (known) ctx_.loop.after(once_timeout_, [this] { on_once_deadline(); });
      if (object_id.empty())
        once_attempts_.clear();
      else
        once_attempts_.erase(object_id);
      break;
    }
    case rigger_vision_TRACK_ONCE_MODEL: {
      const Stamp sent = dds::to_domain(cmd.header.stamp);
      known = request_by_model(object_id, sent > Stamp{} ? sent : std::chrono::system_clock::now());
      break;
    }
    case rigger_vision_TRACK_CONTINUOUS:
      known = schedule_.track_continuous(object_id) || track_by_model(object_id);
      break;
    case rigger_vision_TRACK_STOP: {
      const bool by_model = model_tracker_.stop(object_id);
      known = schedule_.stop(object_id) || by_model;
      break;
    }
    default:
      ctx_.log->warn("command dropped seq={} source={}: unknown kind {}", cmd.seq, dds::to_string(cmd.source),
                     static_cast<int>(cmd.kind));
      return false;
  }
  if (!known && cmd.kind != rigger_vision_TRACK_ONCE_MODEL) {  // request_by_model() says why itself
    ctx_.log->warn("command dropped seq={} source={}: unknown object \"{}\"", cmd.seq, dds::to_string(cmd.source),
                   object_id);
  }
  return known;
}

void VisionTrackerNode::on_once_deadline() {
  // A deadline timer may outlive its request (done, stopped or replaced): expire() only ends overdue ones.
  for (const std::string& id : schedule_.expire(dds::EventLoop::Clock::now())) {
    ctx_.log->warn("track_once timed out object={} timeout_s={}", id, std::chrono::duration<double>(once_timeout_).count());
    ObjectTrack lost;
    lost.object_id = id;
    const OnceAttempt attempt = once_attempts_[id];
    once_attempts_.erase(id);
    std::string detail = fmt::format("{} image{} in {:.1f} s", attempt.images, attempt.images == 1 ? "" : "s",
                                     std::chrono::duration<double>(once_timeout_).count());
    if (attempt.best_markers > 0)
      detail += fmt::format(": best quality {:.2f} from {} markers, under the {:.2f} a TRACK_ONCE takes",
                            attempt.best_quality, attempt.best_markers, once_min_quality_);
    else if (attempt.images > 0)
      detail += ": no pose of it in any";
    publish(lost, std::chrono::system_clock::now(), "NOT_SEEN", detail);
  }
}

void VisionTrackerNode::on_image() {
  images_.take([this](const rigger_vision_Image& image, const dds_sample_info_t&) {
    if (!schedule_.any_active()) {  // nothing tracked: no processing at all
      ++images_ignored_;
      return;
    }
    process(image);
  });
}

void VisionTrackerNode::process(const rigger_vision_Image& image) {
  const std::string encoding = dds::to_string(image.encoding);
  const std::uint64_t expected_bytes = static_cast<std::uint64_t>(image.step) * image.height;
  const auto data = dds::elements(image.data);  // empty when the buffer is null
  const char* problem = nullptr;
  if (encoding != "mono8") problem = "encoding is not mono8";
  else if (image.width == 0 || image.height == 0) problem = "width or height is zero";
  else if (image.step < image.width) problem = "step is less than width";
  else if (data.size() != expected_bytes)
    problem = "data length is not step * height";
  if (problem) {
    ++images_dropped_;
    ctx_.log->warn("image dropped: {} (encoding={} width={} height={} step={} data_bytes={})", problem, encoding,
                   image.width, image.height, image.step, data.size());
    return;
  }
  // A view of the sample's buffer, no copy: the tracker is done with it before the loan returns.
  const cv::Mat view(static_cast<int>(image.height), static_cast<int>(image.width), CV_8UC1,
                     const_cast<std::uint8_t*>(data.data()), image.step);
  const FrameResult result = tracker_.process(view, dds::to_domain(image.header.stamp));
  if (result.status != FrameStatus::kOk) {
    ++images_dropped_;
    ctx_.log->warn("image dropped by the tracker: {}", to_string(result.status));
    return;
  }
  ++images_processed_;
  for (const ObjectTrack& track : result.objects) {
    if (schedule_.once_pending(track.object_id)) {
      OnceAttempt& attempt = once_attempts_[track.object_id];
      ++attempt.images;
      if (track.detected && track.quality > attempt.best_quality) {
        attempt.best_quality = track.quality;
        attempt.best_markers = track.markers_used;
      }
    }
    if (schedule_.on_track(track.object_id, result.stamp, track.detected, track.quality)) publish(track, result.stamp);
  }
}

void VisionTrackerNode::publish(const ObjectTrack& track, Stamp stamp, const std::string& status,
                                const std::string& detail) {
  rigger_vision_TrackedPose out{};
  out.header.stamp = dds::to_wire(stamp);  // the image's stamp; a lost object says so with tracked=false
  // A calibration board is measured to find where the camera is: in the camera's frame, not through the
  // camera pose the cell file gives.
  const bool board = cell::is_calibration_board_id(track.object_id);
  out.header.frame_id = dds::wire_string(board ? camera_id_ : frame_id_);
  out.object_id = dds::wire_string(track.object_id);
  out.tracked = track.detected;
  out.status = dds::wire_string(status);
  out.detail = dds::wire_string(detail);
  if (track.detected) {
    out.pose.pose = dds::to_wire(board ? track.pose_camera_object : track.pose_world_object);
    Eigen::Matrix<double, 6, 6> rotate = Eigen::Matrix<double, 6, 6>::Identity();
    if (board) {
      const Eigen::Matrix3d r_camera_world = tracker_.config().pose_world_camera.linear().transpose();
      rotate.topLeftCorner<3, 3>() = r_camera_world;
      rotate.bottomRightCorner<3, 3>() = r_camera_world;
    }
    dds::covariance_to_wire(rotate * track.covariance_world * rotate.transpose(), out.pose.covariance);
    out.quality = track.quality;
    out.markers_used = static_cast<std::uint32_t>(track.markers_used);
    out.reprojection_error_px = track.reprojection_rms_px;
  } else {
    // Never the last pose under this image's stamp: a lost object carries no pose at all.
    out.pose.pose = dds::to_wire(Eigen::Isometry3d::Identity());
    out.quality = 0.0;
  }
  poses_.write(out);
}

}  // namespace rigger::vision
