#pragma once
/// @file
/// The vision tracker's DDS node: rigger/camera/image in, rigger/tracker/pose out, driven by
/// rigger/tracker/command. The logic is Tracker (tracker.hpp); this is plumbing.

#include <chrono>
#include <cstdint>
#include <string>

#include "rigger/dds/pubsub.hpp"
#include "rigger/dds/service.hpp"
#include "tracker.hpp"
#include "tracking_schedule.hpp"

namespace rigger::vision {

/// Configuration keys (all optional):
///   "cell_file": string, default "deploy/cell/simulated_cell.json" — found by the rule of
///                rigger/base/install.hpp (beside this configuration, then in the data folder)
///   "camera_id": string, default "camera" — the cell entity holding the camera block
///   "frame_id": string, default "world" — frame of the published poses
///   "start_mode": "idle" | "continuous", default "idle" — for every object
///   "lost_after_s": number in [0.01, 10], default 0.5 — the tracker's lost-tracking age
///   "once_min_quality": number in [0, 1], default 0.5 — the quality a pose needs to end a TRACK_ONCE
///   "once_timeout_s": number in [0.05, 60], default 2 — when an unfinished TRACK_ONCE gives up
/// @throws ConfigError for a bad key or an unreadable cell file (exit 2).
///
/// Commands (rigger/tracker/command), per object_id ("" = every object):
///   TRACK_CONTINUOUS  publish the object's track for every image from now on
///   TRACK_ONCE        track the object until it has a pose from an image stamped after the command's
///                     header.stamp with quality >= once_min_quality, publish that one sample, then go
///                     back to what it did before; after once_timeout_s without one, publish tracked=false
///                     for it (stamped with the wall clock) unless it is tracked continuously
///   STOP              neither (a pending TRACK_ONCE is dropped without a sample)
/// While no object is tracked, images are not looked at.
class VisionTrackerNode : public dds::Node {
 public:
  explicit VisionTrackerNode(dds::ServiceContext& ctx);

  /// What is tracked, per object. Loop thread.
  const TrackingSchedule& schedule() const { return schedule_; }
  /// Commands applied / dropped (unknown kind or object). Loop thread.
  std::uint64_t commands_applied() const { return commands_applied_; }
  std::uint64_t commands_dropped() const { return commands_dropped_; }
  /// Images processed by the tracker / images dropped (corrupt, refused by the tracker). Loop thread.
  std::uint64_t images_processed() const { return images_processed_; }
  std::uint64_t images_dropped() const { return images_dropped_; }
  /// Images taken while no object was tracked (not looked at).
  std::uint64_t images_ignored() const { return images_ignored_; }

 private:
  void on_image();
  void on_command();
  void on_once_deadline();
  bool apply(const rigger_vision_TrackerCommand& cmd);
  void process(const rigger_vision_Image& image);
  void publish(const ObjectTrack& track, Stamp stamp);

  dds::ServiceContext& ctx_;
  std::string frame_id_;
  Tracker tracker_;
  TrackingSchedule schedule_;
  std::chrono::nanoseconds once_timeout_;
  std::uint64_t commands_applied_ = 0;
  std::uint64_t commands_dropped_ = 0;
  std::uint64_t images_processed_ = 0;
  std::uint64_t images_dropped_ = 0;
  std::uint64_t images_ignored_ = 0;
  dds::Reader<rigger_vision_Image> images_;
  dds::Reader<rigger_vision_TrackerCommand> commands_;
  dds::Writer<rigger_vision_TrackedPose> poses_;
};

}  // namespace rigger::vision
