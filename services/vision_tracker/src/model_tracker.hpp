#pragma once
/// @file
/// The tracker's markerless TRACK_CONTINUOUS: each object tracked is refined in the newest depth image from
/// where it is predicted to be, and if that is refused from its last pose (localize_mesh() with
/// `tracking`: no search of the whole image), on a thread of its own, so that the node's loop (markers,
/// commands, TRACK_ONCE_MODEL) is never blocked by it. A frame that arrives while one is being searched
/// replaces the one waiting: the work runs at the rate it can, on the newest image. A refused frame keeps the
/// last pose found. No DDS: results go to a callback (on the worker thread).
///
/// The prediction: an object held by the robot (the robot's tool within its box when it was last found)
/// moves with the tool, whose poses the robot's state gives (tool_pose()); it is searched for where the tool
/// has carried it since, however many images were refused in between. Any other object is searched for where
/// the velocity between its last two poses would have taken it (at most kMaxPredictionS ahead).

#include <Eigen/Geometry>

#include <chrono>
#include <condition_variable>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "model_localizer.hpp"
#include "tracker_config.hpp"

namespace rigger::vision {

/// What the tracking cost over a period (ModelTracker's Report): what an integrator sizes the tracker's
/// core by.
struct ModelTrackerFigures {
  std::chrono::steady_clock::duration period{};
  int frames = 0;          ///< depth images searched (each for every object tracked)
  int skipped = 0;         ///< images replaced by a newer one before they were searched
  int objects = 0;         ///< objects tracked at the end of the period
  int refused = 0;         ///< searches that gave no pose (a code instead)
  double lowest_model_support = 1.0;  ///< of the poses found (perception::LocalizeResult::model_support)
  double frame_ms_p50 = 0.0, frame_ms_max = 0.0;  ///< wall time per image searched
  double cpu_ms_p50 = 0.0;  ///< the worker thread's CPU time per image searched
  double busy_share = 0.0;  ///< the worker's CPU time over the period's wall time
};

class ModelTracker {
 public:
  /// Called on the worker thread for every object searched in a frame, with the frame's stamp.
  using Publish = std::function<void(const std::string& object_id, Stamp stamp, const ModelLocalization& result)>;
  /// Called on the worker thread every kReportPeriod while objects are tracked, and when the last one stops.
  using Report = std::function<void(const ModelTrackerFigures& figures)>;
  static constexpr std::chrono::seconds kReportPeriod{10};
  /// How far ahead a track is predicted from its last two poses (a servo moves a held load centimetres
  /// between two depth images; a part not found for longer is searched for where it was last found).
  static constexpr double kMaxPredictionS = 1.0;
  /// A prediction this near the last pose is not searched from again.
  static constexpr double kSamePlaceM = 0.005;

  explicit ModelTracker(Publish publish, Report report = {});
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

  /// The newest depth image, stamped; replaces one not yet taken up. False (dropped) while nothing is tracked.
  bool submit(perception::DepthFrame frame, Stamp stamp);

  /// The robot's tool in the world at `stamp` (from the robot's state, in stamp order). Kept for
  /// kToolHistoryS; an image is matched with the tool pose nearest its stamp, within kToolMatchS.
  void tool_pose(Stamp stamp, const Eigen::Isometry3d& pose_world_tool);
  static constexpr double kToolHistoryS = 5.0;
  static constexpr double kToolMatchS = 0.05;
  /// An object is held when the tool lies within its box grown by this at the pose found.
  static constexpr double kHeldMarginM = 0.02;

 private:
  struct Track {
    std::shared_ptr<const perception::Mesh> mesh;
    std::optional<Eigen::Isometry3d> pose_world_object;  ///< the last pose found (or the start)
    std::uint64_t generation = 0;  // a start() or stop() since the worker took it up makes its result stale
    std::optional<Stamp> stamp;    ///< of the image the last pose was found in (unset: the start)
    Eigen::Vector3d linear_mps = Eigen::Vector3d::Zero();     ///< between the last two poses found
    Eigen::Vector3d angular_radps = Eigen::Vector3d::Zero();  ///< world frame
    Eigen::AlignedBox3d box_m;  ///< the mesh's bounding box, object frame
    /// Set while held by the robot: the object in the tool's frame when it was last found.
    std::optional<Eigen::Isometry3d> pose_tool_object;
  };
  using ToolPoses = std::vector<std::pair<Stamp, Eigen::Isometry3d>>;
  /// The tool pose of `poses` nearest `stamp` within kToolMatchS, if any.
  static std::optional<Eigen::Isometry3d> tool_at(const ToolPoses& poses, Stamp stamp);
  /// Held: where the tool at the image's stamp carries the object. Otherwise the last pose moved on at the
  /// velocity between the last two, to the image's stamp (up to kMaxPredictionS after the last pose; later,
  /// the last pose).
  static std::optional<Eigen::Isometry3d> predicted(const Track& track, const std::optional<Eigen::Isometry3d>& tool,
                                                    Stamp stamp);
  /// Takes `pose`, found in the image of `stamp`, as the track's last, with the velocity it implies, and
  /// whether the tool (its pose at that stamp, if known) holds it.
  static void follow(Track& track, const Eigen::Isometry3d& pose, Stamp stamp, const std::optional<Eigen::Isometry3d>& tool);
  /// The object in `frame`: from the predicted pose, and if that is refused from the last pose found.
  static ModelLocalization search(const Track& track, const perception::DepthFrame& frame, Stamp stamp,
                                  const std::optional<Eigen::Isometry3d>& tool);
  void run();
  /// After a frame (or with `last`, when tracking ended): reports the figures when the period is over.
  void account(std::chrono::steady_clock::time_point frame_start, double frame_ms, double cpu_ms, bool last);

  Publish publish_;
  Report report_;
  // The worker's figures since the last report (worker thread only).
  std::optional<std::chrono::steady_clock::time_point> period_start_;  // unset: since no frame was searched
  std::vector<double> frame_ms_, cpu_ms_;
  int refused_ = 0;
  double lowest_support_ = 1.0;
  int skipped_ = 0;  // guarded by mutex_
  mutable std::mutex mutex_;
  std::condition_variable wake_;
  bool quit_ = false;
  bool report_due_ = false;  // the last object stopped: the figures so far are reported
  std::uint64_t generations_ = 0;
  std::map<std::string, Track> tracks_;
  std::optional<std::pair<perception::DepthFrame, Stamp>> waiting_;
  ToolPoses tool_poses_;  // oldest first
  std::thread worker_;  // last: it uses the members above
};

}  // namespace rigger::vision
