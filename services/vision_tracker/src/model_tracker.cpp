#include "model_tracker.hpp"

#include <vector>

namespace rigger::vision {

ModelTracker::ModelTracker(Publish publish) : publish_(std::move(publish)), worker_([this] { run(); }) {}

ModelTracker::~ModelTracker() {
  {
    const std::lock_guard<std::mutex> lock(mutex_);
    quit_ = true;
  }
  wake_.notify_all();
  worker_.join();
}

void ModelTracker::start(const std::string& object_id, std::shared_ptr<const perception::Mesh> mesh,
                         const std::optional<Eigen::Isometry3d>& start_world_object) {
  const std::lock_guard<std::mutex> lock(mutex_);
  tracks_[object_id] = Track{std::move(mesh), start_world_object, ++generations_};
}

bool ModelTracker::stop(const std::string& object_id) {
  const std::lock_guard<std::mutex> lock(mutex_);
  if (object_id.empty()) {
    const bool any = !tracks_.empty();
    tracks_.clear();
    if (!any) waiting_.reset();
    return any;
  }
  const bool erased = tracks_.erase(object_id) != 0;
  if (tracks_.empty()) waiting_.reset();
  return erased;
}

bool ModelTracker::tracking(const std::string& object_id) const {
  const std::lock_guard<std::mutex> lock(mutex_);
  return tracks_.count(object_id) != 0;
}

bool ModelTracker::any() const {
  const std::lock_guard<std::mutex> lock(mutex_);
  return !tracks_.empty();
}

void ModelTracker::submit(perception::DepthFrame frame, Stamp stamp) {
  {
    const std::lock_guard<std::mutex> lock(mutex_);
    if (tracks_.empty()) return;
    waiting_.emplace(std::move(frame), stamp);
  }
  wake_.notify_all();
}

void ModelTracker::run() {
  std::unique_lock<std::mutex> lock(mutex_);
  for (;;) {
    wake_.wait(lock, [this] { return quit_ || waiting_.has_value(); });
    if (quit_) return;
    const std::pair<perception::DepthFrame, Stamp> frame = std::move(*waiting_);
    waiting_.reset();
    const std::map<std::string, Track> work = tracks_;  // meshes shared, not copied
    lock.unlock();
    std::vector<std::pair<std::string, ModelLocalization>> results;
    for (const auto& [id, track] : work) {
      results.emplace_back(id, localize_mesh(*track.mesh, frame.first, track.pose_world_object, true));
    }
    lock.lock();
    for (const auto& [id, result] : results) {
      const auto now = tracks_.find(id);
      if (now == tracks_.end() || now->second.generation != work.at(id).generation) continue;  // stopped or restarted
      if (result.found()) now->second.pose_world_object = result.pose_world_object;
      lock.unlock();
      publish_(id, frame.second, result);
      lock.lock();
    }
  }
}

}  // namespace rigger::vision
