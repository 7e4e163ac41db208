#include "model_tracker.hpp"

#include <algorithm>
#include <cmath>
#include <ctime>
#include <iterator>

namespace rigger::vision {

namespace {

/// The calling thread's CPU time, ms.
double thread_cpu_ms() {
  timespec t{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
  return static_cast<double>(t.tv_sec) * 1e3 + static_cast<double>(t.tv_nsec) * 1e-6;
}

double median(std::vector<double> v) {
  if (v.empty()) return 0.0;
  const auto middle = v.begin() + static_cast<std::ptrdiff_t>(v.size() / 2);
  std::nth_element(v.begin(), middle, v.end());
  return *middle;
}

}  // namespace

ModelTracker::ModelTracker(Publish publish, Report report)
    : publish_(std::move(publish)), report_(std::move(report)), worker_([this] { run(); }) {}

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
  Track track;
  for (const Eigen::Vector3d& v : mesh->vertices_m) track.box_m.extend(v);
  track.mesh = std::move(mesh);
  track.pose_world_object = start_world_object;
  track.generation = ++generations_;
  tracks_[object_id] = std::move(track);
}

bool ModelTracker::stop(const std::string& object_id) {
  bool stopped = false;
  {
    const std::lock_guard<std::mutex> lock(mutex_);
    const bool any_before = !tracks_.empty();
    if (object_id.empty()) {
      stopped = any_before;
      tracks_.clear();
    } else {
      stopped = tracks_.erase(object_id) != 0;
    }
    if (!tracks_.empty()) return stopped;
    waiting_.reset();
    if (any_before) report_due_ = true;  // the figures of the tracking that just ended
  }
  wake_.notify_all();
  return stopped;
}

bool ModelTracker::tracking(const std::string& object_id) const {
  const std::lock_guard<std::mutex> lock(mutex_);
  return tracks_.count(object_id) != 0;
}

bool ModelTracker::any() const {
  const std::lock_guard<std::mutex> lock(mutex_);
  return !tracks_.empty();
}

bool ModelTracker::submit(perception::DepthFrame frame, Stamp stamp) {
  {
    const std::lock_guard<std::mutex> lock(mutex_);
    if (tracks_.empty()) return false;
    if (waiting_) ++skipped_;
    waiting_.emplace(std::move(frame), stamp);
  }
  wake_.notify_all();
  return true;
}

void ModelTracker::tool_pose(Stamp stamp, const Eigen::Isometry3d& pose_world_tool) {
  const std::lock_guard<std::mutex> lock(mutex_);
  if (!tool_poses_.empty() && stamp <= tool_poses_.back().first) return;  // out of order: dropped
  tool_poses_.emplace_back(stamp, pose_world_tool);
  const Stamp oldest = stamp - std::chrono::duration_cast<Stamp::duration>(std::chrono::duration<double>(kToolHistoryS));
  const auto keep = std::find_if(tool_poses_.begin(), tool_poses_.end(), [&](const auto& p) { return p.first >= oldest; });
  tool_poses_.erase(tool_poses_.begin(), keep);
}

std::optional<Eigen::Isometry3d> ModelTracker::tool_at(const ToolPoses& poses, Stamp stamp) {
  const auto after = std::lower_bound(poses.begin(), poses.end(), stamp,
                                      [](const auto& p, Stamp s) { return p.first < s; });
  std::optional<Eigen::Isometry3d> best;
  double best_s = kToolMatchS;
  for (auto it : {after, after == poses.begin() ? poses.end() : std::prev(after)}) {
    if (it == poses.end()) continue;
    const double off_s = std::abs(std::chrono::duration<double>(it->first - stamp).count());
    if (off_s <= best_s) best_s = off_s, best = it->second;
  }
  return best;
}

std::optional<Eigen::Isometry3d> ModelTracker::predicted(const Track& track, const std::optional<Eigen::Isometry3d>& tool,
                                                         Stamp stamp) {
  if (track.pose_tool_object && tool) return *tool * *track.pose_tool_object;
  if (!track.pose_world_object || !track.stamp) return track.pose_world_object;
  const double dt = std::chrono::duration<double>(stamp - *track.stamp).count();
  if (!(dt > 0.0 && dt <= kMaxPredictionS)) return track.pose_world_object;
  Eigen::Isometry3d pose = *track.pose_world_object;
  pose.translation() += track.linear_mps * dt;
  const Eigen::Vector3d turn = track.angular_radps * dt;
  if (turn.norm() > 0.0) pose.linear() = Eigen::AngleAxisd(turn.norm(), turn.normalized()) * pose.linear();
  return pose;
}

void ModelTracker::follow(Track& track, const Eigen::Isometry3d& pose, Stamp stamp,
                          const std::optional<Eigen::Isometry3d>& tool) {
  track.pose_tool_object.reset();
  if (tool) {
    const Eigen::Vector3d margin = Eigen::Vector3d::Constant(kHeldMarginM);
    const Eigen::AlignedBox3d held(track.box_m.min() - margin, track.box_m.max() + margin);
    if (held.contains(pose.inverse() * tool->translation())) track.pose_tool_object = tool->inverse() * pose;
  }
  track.linear_mps.setZero();
  track.angular_radps.setZero();
  if (track.pose_world_object && track.stamp) {
    const double dt = std::chrono::duration<double>(stamp - *track.stamp).count();
    if (dt > 0.0 && dt <= kMaxPredictionS) {
      track.linear_mps = (pose.translation() - track.pose_world_object->translation()) / dt;
      const Eigen::AngleAxisd turn(pose.linear() * track.pose_world_object->linear().transpose());
      track.angular_radps = turn.axis() * turn.angle() / dt;
    }
  }
  track.pose_world_object = pose;
  track.stamp = stamp;
}

ModelLocalization ModelTracker::search(const Track& track, const perception::DepthFrame& frame, Stamp stamp,
                                       const std::optional<Eigen::Isometry3d>& tool) {
  const std::optional<Eigen::Isometry3d> ahead = predicted(track, tool, stamp);
  ModelLocalization result = localize_mesh(*track.mesh, frame, ahead, true);
  // It may have stopped meanwhile (a servo stops without poses): then from where it was last found.
  if (!result.found() && ahead && track.pose_world_object &&
      (ahead->translation() - track.pose_world_object->translation()).norm() > kSamePlaceM) {
    ModelLocalization still = localize_mesh(*track.mesh, frame, track.pose_world_object, true);
    if (still.found()) return still;
  }
  return result;
}

void ModelTracker::run() {
  std::unique_lock<std::mutex> lock(mutex_);
  for (;;) {
    wake_.wait(lock, [this] { return quit_ || waiting_.has_value() || report_due_; });
    if (quit_) return;
    if (!waiting_) {  // the last object stopped
      report_due_ = false;
      lock.unlock();
      account(std::chrono::steady_clock::now(), 0.0, 0.0, true);
      lock.lock();
      continue;
    }
    const std::pair<perception::DepthFrame, Stamp> frame = std::move(*waiting_);
    waiting_.reset();
    const std::map<std::string, Track> work = tracks_;  // meshes shared, not copied
    const std::optional<Eigen::Isometry3d> tool = tool_at(tool_poses_, frame.second);
    lock.unlock();
    const auto wall_start = std::chrono::steady_clock::now();
    const double cpu_start = thread_cpu_ms();
    std::vector<std::pair<std::string, ModelLocalization>> results;
    for (const auto& [id, track] : work) {
      results.emplace_back(id, search(track, frame.first, frame.second, tool));
      const ModelLocalization& r = results.back().second;
      if (!r.found()) ++refused_;
      else lowest_support_ = std::min(lowest_support_, r.result.model_support);
    }
    const double cpu_ms = thread_cpu_ms() - cpu_start;
    const double wall_ms =
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - wall_start).count();
    lock.lock();
    for (const auto& [id, result] : results) {
      const auto now = tracks_.find(id);
      if (now == tracks_.end() || now->second.generation != work.at(id).generation) continue;  // stopped or restarted
      if (result.found()) follow(now->second, result.pose_world_object, frame.second, tool);
      lock.unlock();
      publish_(id, frame.second, result);
      lock.lock();
    }
    lock.unlock();
    account(wall_start, wall_ms, cpu_ms, false);
    lock.lock();
  }
}

void ModelTracker::account(std::chrono::steady_clock::time_point frame_start, double frame_ms, double cpu_ms,
                           bool last) {
  if (!period_start_) period_start_ = frame_start;  // the first frame since tracking began
  if (!last) {
    frame_ms_.push_back(frame_ms);
    cpu_ms_.push_back(cpu_ms);
  }
  const auto now = std::chrono::steady_clock::now();
  if (!last && now - *period_start_ < kReportPeriod) return;
  ModelTrackerFigures figures;
  figures.period = now - *period_start_;
  figures.frames = static_cast<int>(frame_ms_.size());
  {
    const std::lock_guard<std::mutex> lock(mutex_);
    figures.skipped = skipped_;
    skipped_ = 0;
    figures.objects = static_cast<int>(tracks_.size());
  }
  figures.refused = refused_;
  figures.lowest_model_support = lowest_support_;
  refused_ = 0;
  lowest_support_ = 1.0;
  figures.frame_ms_p50 = median(frame_ms_);
  figures.frame_ms_max = frame_ms_.empty() ? 0.0 : *std::max_element(frame_ms_.begin(), frame_ms_.end());
  figures.cpu_ms_p50 = median(cpu_ms_);
  double cpu_total_ms = 0.0;
  for (const double ms : cpu_ms_) cpu_total_ms += ms;
  const double period_ms = std::chrono::duration<double, std::milli>(figures.period).count();
  figures.busy_share = period_ms > 0.0 ? cpu_total_ms / period_ms : 0.0;
  frame_ms_.clear();
  cpu_ms_.clear();
  period_start_ = last ? std::nullopt : std::optional(now);
  if (report_ && figures.frames > 0) report_(figures);
}

}  // namespace rigger::vision
