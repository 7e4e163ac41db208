#include "tracking_schedule.hpp"

namespace rigger::vision {

TrackingSchedule::TrackingSchedule(const std::vector<std::string>& object_ids, double once_min_quality)
    : once_min_quality_(once_min_quality) {
  for (const std::string& id : object_ids) objects_.emplace(id, ObjectState{});
}

std::vector<std::string> TrackingSchedule::set_objects(const std::vector<std::string>& object_ids) {
  std::map<std::string, ObjectState> kept;
  for (const std::string& id : object_ids) {
    const auto found = objects_.find(id);
    kept.emplace(id, found == objects_.end() ? ObjectState{} : found->second);
  }
  std::vector<std::string> dropped_once;
  for (const auto& [id, state] : objects_) {
    if (state.once && kept.count(id) == 0) dropped_once.push_back(id);
  }
  objects_ = std::move(kept);
  return dropped_once;
}

template <typename Change>
bool TrackingSchedule::apply(const std::string& object_id, Change change) {
  if (object_id.empty()) {
    for (auto& entry : objects_) change(entry.second);
    return true;
  }
  const auto it = objects_.find(object_id);
  if (it == objects_.end()) return false;
  change(it->second);
  return true;
}

bool TrackingSchedule::track_once(const std::string& object_id, Stamp fresh_after, SteadyTime deadline) {
  return apply(object_id, [&](ObjectState& state) { state.once = Once{fresh_after, deadline}; });
}

bool TrackingSchedule::track_continuous(const std::string& object_id) {
  return apply(object_id, [](ObjectState& state) { state.continuous = true; });
}

bool TrackingSchedule::stop(const std::string& object_id) {
  return apply(object_id, [](ObjectState& state) { state = ObjectState{}; });
}

bool TrackingSchedule::any_active() const {
  for (const auto& entry : objects_) {
    if (entry.second.continuous || entry.second.once) return true;
  }
  return false;
}

bool TrackingSchedule::continuous(const std::string& object_id) const {
  const auto it = objects_.find(object_id);
  return it != objects_.end() && it->second.continuous;
}

bool TrackingSchedule::once_pending(const std::string& object_id) const {
  const auto it = objects_.find(object_id);
  return it != objects_.end() && it->second.once.has_value();
}

bool TrackingSchedule::on_track(const std::string& object_id, Stamp image_stamp, bool detected, double quality) {
  const auto it = objects_.find(object_id);
  if (it == objects_.end()) return false;
  ObjectState& state = it->second;
  const bool ends_once =
      state.once && detected && quality >= once_min_quality_ && image_stamp > state.once->fresh_after;
  if (ends_once) state.once.reset();
  return state.continuous || ends_once;
}

std::vector<std::string> TrackingSchedule::expire(SteadyTime now) {
  std::vector<std::string> expired;
  for (auto& [id, state] : objects_) {
    if (state.once && state.once->deadline <= now) {
      state.once.reset();
      if (!state.continuous) expired.push_back(id);
    }
  }
  return expired;
}

}  // namespace rigger::vision
