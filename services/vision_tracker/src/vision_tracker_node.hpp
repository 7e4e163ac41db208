#pragma once
/// @file
/// The vision tracker's DDS node: rigger/camera/image in, rigger/tracker/pose out, driven by
/// rigger/tracker/command. The logic is Tracker (tracker.hpp); this is plumbing.

#include <chrono>
#include <cstdint>
#include <filesystem>
#include <map>
#include <string>

#include "rigger/base/settings.hpp"
#include "rigger/cell_follower/cell_follower.hpp"
#include "rigger/dds/pubsub.hpp"
#include "rigger/service/service.hpp"
#include "rigger/vision_tracker/settings.hpp"
#include "model_localizer.hpp"
#include "model_tracker.hpp"
#include "tracker.hpp"
#include "tracking_schedule.hpp"

namespace rigger::vision {

/// The vision tracker's configuration (durations in the units of their keys' names).
struct VisionTrackerSettings {
  std::filesystem::path cell_file;
  std::string camera_id;  ///< the cell entity holding the camera block
  std::string frame_id;   ///< frame of the published poses
  bool continuous{};      ///< start_mode: track every object from the start
  std::chrono::nanoseconds lost_after{};
  double once_min_quality{};
  std::chrono::nanoseconds once_timeout{};
};

/// The node reads vision_tracker_settings() from its configuration.
/// @throws ConfigError for a bad key or an unreadable cell file (exit 2).
///
/// Commands (rigger/tracker/command), per object_id ("" = every object):
///   TRACK_CONTINUOUS  publish the object's track for every image from now on
///   TRACK_ONCE        track the object until it has a pose from an image stamped after the command's
///                     header.stamp with quality >= once_min_quality, publish that one sample, then go
///                     back to what it did before; after once_timeout_s without one, publish tracked=false
///                     for it (stamped with the wall clock; status NOT_SEEN, detail: the images looked at
///                     and the best quality found in them) unless it is tracked continuously
///   STOP              neither (a pending TRACK_ONCE is dropped without a sample)
///   TRACK_ONCE_MODEL  without markers: the first depth image (rigger/camera/depth) stamped after the
///                     command is searched for the object by its STEP model (ModelLocalizer), starting
///                     from its pose in the world model (rigger/world/entity) when the world model has
///                     one in frame_id; exactly one sample answers it: tracked=true with status FOUND, or
///                     tracked=false with the status code saying why (NO_MODEL at once for an object
///                     without a model, NO_DEPTH after once_timeout_s without a depth image). The
///                     search runs on the loop thread (a fraction of a second per request).
///   TRACK_CONTINUOUS of an object without markers but with a STEP model: tracked by its model (ModelTracker,
///                     on a thread of its own) from its pose in the world model (or a search of the whole
///                     first depth image), each depth image's result published as it is ready (a few per
///                     second): tracked=true with status FOUND, or tracked=false with the code of the refusal
///                     (the next image starts again from the last pose found). STOP ends it. "" (every
///                     object) means the objects with markers only.
/// While no object is tracked, images are not looked at; depth images only while a TRACK_ONCE_MODEL is
/// pending.
/// A robot's calibration board (cell file calibration_board) is an object too, by cell::calibration_board_id
/// ("robot/calibration_board"); its poses are in the camera's optical frame (header.frame_id the camera id), so
/// that the camera's pose can be solved from them whatever the cell file says it is.
///
/// The node follows the cell's revisions (rigger/world/cell): a revision that changes the camera or a marker
/// layout gives a new tracker (its tracks start afresh; what each kept object was asked to do stays, a new
/// object starts idle, a removed object's pending TRACK_ONCE is answered with tracked=false); any other
/// revision leaves the tracker as it is. A revision without the camera, or with layouts the tracker cannot
/// use, is refused and the tracker keeps the running one.
class VisionTrackerNode : public service::Node {
 public:
  explicit VisionTrackerNode(service::ServiceContext& ctx)
      : VisionTrackerNode(ctx, read_settings(ctx.config, vision_tracker_settings())) {}
  VisionTrackerNode(service::ServiceContext& ctx, const VisionTrackerSettings& settings);
  VisionTrackerNode(service::ServiceContext& ctx, const VisionTrackerSettings& settings, const cell::CellFile& cell_file);

  /// What is tracked, per object. Loop thread.
  const TrackingSchedule& schedule() const { return schedule_; }
  /// Commands applied / dropped (unknown kind or object). Loop thread.
  std::uint64_t commands_applied() const { return commands_applied_; }
  std::uint64_t commands_dropped() const { return commands_dropped_; }
  /// Images processed by the tracker / images dropped (corrupt, refused by the tracker). Loop thread.
  std::uint64_t images_processed() const { return images_processed_; }
  std::uint64_t images_dropped() const { return images_dropped_; }
  /// The cell revision follower. Loop thread.
  const cell_follower::CellFollower& cell_follower() const { return follower_; }
  /// Images taken while no object was tracked (not looked at).
  std::uint64_t images_ignored() const { return images_ignored_; }

 private:
  void on_image();
  void on_command();
  void on_once_deadline();
  bool apply(const rigger_vision_TrackerCommand& cmd);
  void process(const rigger_vision_Image& image);
  /// `status` and `detail` say why a TRACK_ONCE ended without a pose (empty otherwise).
  void publish(const ObjectTrack& track, Stamp stamp, const std::string& status = "", const std::string& detail = "");
  void on_depth();
  void on_entities();
  /// The robot's tool in the world, handed to the model tracking (a held object moves with it).
  void on_robot_state();
  bool request_by_model(const std::string& object_id, Stamp fresh_after);
  bool track_by_model(const std::string& object_id);
  /// Fills `frame` from a depth image; why it cannot, or nullptr.
  const char* depth_frame(const rigger_vision_Image& image, perception::DepthFrame& frame) const;
  void localize_by_model(Stamp stamp, const perception::DepthFrame& frame, const char* problem);
  void on_model_deadline();
  void publish_model(const std::string& object_id, Stamp stamp, const ModelLocalization& result);
  cell_follower::Outcome on_revision(const cell_follower::FollowedRevision& revision);

  service::ServiceContext& ctx_;
  std::string frame_id_;
  std::string camera_id_;
  std::chrono::nanoseconds lost_after_;
  Tracker tracker_;
  TrackingSchedule schedule_;
  std::chrono::nanoseconds once_timeout_;
  double once_min_quality_;
  /// Per object with a pending TRACK_ONCE: what its images gave so far (the NOT_SEEN answer's detail).
  struct OnceAttempt {
    int images = 0;
    double best_quality = 0.0;
    int best_markers = 0;
  };
  std::map<std::string, OnceAttempt> once_attempts_;
  std::uint64_t commands_applied_ = 0;
  std::uint64_t commands_dropped_ = 0;
  std::uint64_t images_processed_ = 0;
  std::uint64_t images_dropped_ = 0;
  std::uint64_t images_ignored_ = 0;
  /// A pending TRACK_ONCE_MODEL: answered by the first depth image stamped after fresh_after.
  struct ModelRequest {
    Stamp fresh_after;
    dds::EventLoop::Clock::time_point deadline;
  };
  std::map<std::string, ModelRequest> model_requests_;
  ModelLocalizer model_localizer_;
  /// The world model's poses of the objects in frame_id (the priors of TRACK_ONCE_MODEL).
  std::map<std::string, Eigen::Isometry3d> world_poses_;
  /// The cell's entities in the world (the robot's base, for the robot's tool pose); set with each revision.
  cell::CellFile cell_;
  bool robot_frame_warned_ = false;
  dds::Reader<rigger_vision_Image> images_;
  dds::Reader<rigger_vision_Image> depth_;
  dds::Reader<rigger_world_EntityState> entities_;
  dds::Reader<rigger_robot_RobotState> robot_states_;
  dds::Reader<rigger_vision_TrackerCommand> commands_;
  dds::Writer<rigger_vision_TrackedPose> poses_;
  /// Markerless TRACK_CONTINUOUS; its results are posted to the loop thread and published there.
  ModelTracker model_tracker_;
  cell_follower::CellFollower follower_;  // last: its callback uses the members above
};

}  // namespace rigger::vision
