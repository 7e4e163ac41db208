#pragma once
/// @file
/// The tracker's markerless TRACK_CONTINUOUS: each object tracked is refined from its last pose in the
/// newest depth image (localize_mesh() with `tracking`: no search of the whole image), on a thread of its
/// own, so that the node's loop (markers, commands, TRACK_ONCE_MODEL) is never blocked by it. A frame that
/// arrives while one is being searched replaces the one waiting: the work runs at the rate it can, on the
/// newest image. A refused frame keeps the last pose to start the next one from. No DDS: results go to a
/// callback (on the worker thread).

#include <Eigen/Geometry>

#include <condition_variable>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>

#include "model_localizer.hpp"
#include "tracker_config.hpp"

namespace rigger::vision {

class ModelTracker {
 public:
  /// Called on the worker thread for every object searched in a frame, with the frame's stamp.
  using Publish = std::function<void(const std::string& object_id, Stamp stamp, const ModelLocalization& result)>;

  explicit ModelTracker(Publish publish);
  /// Stops the worker (after the frame it is on).
  ~ModelTracker();
  ModelTracker(const ModelTracker&) = delete;
  ModelTracker& operator=(const ModelTracker&) = delete;

  /// Tracks `object_id` (replacing its track) from `start_world_object`, or, unset, from a search of the
  /// whole first frame.
  void start(const std::string& object_id, std::shared_ptr<const perception::Mesh> mesh,
             const std::optional<Eigen::Isometry3d>& start_world_object);
  /// Stops tracking `object_id` ("" = every object); false when it was not tracked.
  bool stop(const std::string& object_id);
  bool tracking(const std::string& object_id) const;
  bool any() const;

  /// The newest depth image, stamped; replaces one not yet taken up.
  void submit(perception::DepthFrame frame, Stamp stamp);

 private:
  struct Track {
    std::shared_ptr<const perception::Mesh> mesh;
    std::optional<Eigen::Isometry3d> pose_world_object;
    std::uint64_t generation = 0;  // a start() or stop() since the worker took it up makes its result stale
  };
  void run();

  Publish publish_;
  mutable std::mutex mutex_;
  std::condition_variable wake_;
  bool quit_ = false;
  std::uint64_t generations_ = 0;
  std::map<std::string, Track> tracks_;
  std::optional<std::pair<perception::DepthFrame, Stamp>> waiting_;
  std::thread worker_;  // last: it uses the members above
};

}  // namespace rigger::vision
