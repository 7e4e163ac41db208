#pragma once
/// @file
/// The vision tracker's DDS node: rigger/camera/image in, rigger/tracker/pose out, driven by
/// rigger/tracker/command. The logic is Tracker (tracker.hpp); this is plumbing.

#include <cstdint>
#include <string>

#include "rigger/dds/pubsub.hpp"
#include "rigger/dds/service.hpp"
#include "rigger/sim/camera_scene.hpp"
#include "tracker.hpp"

namespace rigger::vision {

inline constexpr const char* kImageTopic = "rigger/camera/image";
inline constexpr const char* kPoseTopic = "rigger/tracker/pose";
inline constexpr const char* kCommandTopic = "rigger/tracker/command";

/// The tracker configuration (camera intrinsics and pose, marker layouts, dictionary) of a cell
/// configuration's camera scene; tuning keeps its defaults.
TrackerConfig tracker_config_from_cell_scene(const sim::CameraScene& scene);

/// What the node does with images.
enum class TrackerMode {
  kIdle,        ///< images are taken and dropped unprocessed
  kOnce,        ///< the next valid image is processed, then idle
  kContinuous,  ///< every image is processed
};

/// Configuration keys (all optional):
///   "cell_file": string, default "deploy/cell/simulated_cell.json" — absolute, relative to the working
///                directory, or else relative to the repository root (RIGGER_SOURCE_DIR)
///   "camera_id": string, default "camera" — the cell entity holding the camera block
///   "frame_id": string, default "world" — frame of the published poses
///   "start_mode": "idle" | "continuous", default "idle"
///   "lost_after_s": number in [0.01, 10], default 0.5 — the tracker's lost-tracking age
/// @throws ConfigError for a bad key or an unreadable cell file (exit 2).
class VisionTrackerNode : public dds::Node {
 public:
  explicit VisionTrackerNode(dds::ServiceContext& ctx);

  TrackerMode mode() const { return mode_; }
  /// Images processed by the tracker / images dropped (corrupt, refused by the tracker). Loop thread.
  std::uint64_t images_processed() const { return images_processed_; }
  std::uint64_t images_dropped() const { return images_dropped_; }
  /// Images taken while idle (not looked at).
  std::uint64_t images_ignored() const { return images_ignored_; }

 private:
  void on_image();
  void on_command();
  void process(const rigger_vision_Image& image);
  void publish(const FrameResult& result);

  dds::ServiceContext& ctx_;
  std::string frame_id_;
  Tracker tracker_;
  TrackerMode mode_ = TrackerMode::kIdle;
  std::uint64_t images_processed_ = 0;
  std::uint64_t images_dropped_ = 0;
  std::uint64_t images_ignored_ = 0;
  dds::Reader<rigger_vision_Image> images_;
  dds::Reader<rigger_vision_TrackerCommand> commands_;
  dds::Writer<rigger_vision_TrackedPose> poses_;
};

}  // namespace rigger::vision
