#pragma once
/// @file
/// Which objects the vision tracker tracks, driven by rigger/tracker/command: per object, continuous
/// tracking on or off, and at most one pending TRACK_ONCE. A TRACK_ONCE ends at the object's first pose
/// from an image stamped after the request with quality >= the configured minimum, or at its deadline;
/// the object then returns to what it did before (idle or continuous). Pure logic: no DDS, no clock
/// reads. Not thread-safe (the node's loop thread owns it).

#include <chrono>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "tracker_config.hpp"

namespace rigger::vision {

/// Deadlines of TRACK_ONCE requests (the event loop's clock).
using SteadyTime = std::chrono::steady_clock::time_point;

class TrackingSchedule {
 public:
  /// `object_ids`: the objects the tracker knows; `once_min_quality` in [0, 1]: the quality a pose needs
  /// to end a TRACK_ONCE.
  TrackingSchedule(const std::vector<std::string>& object_ids, double once_min_quality);

  /// TRACK_ONCE for `object_id` ("" = every object): track it until a pose from an image stamped after
  /// `fresh_after` has quality >= once_min_quality, or until `deadline`. Replaces a pending request.
  /// @return false for an unknown object (nothing changes).
  bool track_once(const std::string& object_id, Stamp fresh_after, SteadyTime deadline);
  /// TRACK_CONTINUOUS for `object_id` ("" = every object). @return false for an unknown object.
  bool track_continuous(const std::string& object_id);
  /// STOP for `object_id` ("" = every object): continuous tracking off and a pending TRACK_ONCE dropped
  /// (nothing is published for it). @return false for an unknown object.
  bool stop(const std::string& object_id);

  /// The objects the tracker knows become `object_ids` (a new cell revision): the state of an object kept is
  /// kept, a new object starts idle, a removed one is dropped with its pending TRACK_ONCE. @return the
  /// removed objects that had a TRACK_ONCE pending (to be published as not tracked).
  std::vector<std::string> set_objects(const std::vector<std::string>& object_ids);

  /// True when some object is tracked: images must be processed.
  bool any_active() const;
  /// The object is tracked continuously (whatever TRACK_ONCE is pending). False for unknown objects.
  bool continuous(const std::string& object_id) const;
  /// A TRACK_ONCE is pending for the object. False for unknown objects.
  bool once_pending(const std::string& object_id) const;

  /// Whether to publish `object_id`'s track from the image stamped `image_stamp`: always while it is
  /// tracked continuously; for a pending TRACK_ONCE only the track that ends it (detected, fresh and
  /// good enough), which completes the request.
  bool on_track(const std::string& object_id, Stamp image_stamp, bool detected, double quality);

  /// Ends the TRACK_ONCE requests whose deadline is at or before `now`; returns those of their objects
  /// that are not tracked continuously, to be published as not tracked (a continuously tracked object's
  /// own stream already says, image by image, how it is tracked).
  std::vector<std::string> expire(SteadyTime now);

 private:
  struct Once {
    Stamp fresh_after;
    SteadyTime deadline;
  };
  struct ObjectState {
    bool continuous = false;
    std::optional<Once> once;
  };

  // Applies `change` to the named object's state, or to every object's for "".
  template <typename Change>
  bool apply(const std::string& object_id, Change change);

  std::map<std::string, ObjectState> objects_;
  double once_min_quality_;
};

}  // namespace rigger::vision
