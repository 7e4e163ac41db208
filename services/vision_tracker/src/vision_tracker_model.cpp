// The vision tracker node's markerless path (TRACK_ONCE_MODEL, and TRACK_CONTINUOUS of an object without
// markers): depth images and the world model's poses in, rigger/tracker/pose out. The search itself is
// ModelLocalizer's, the continuous tracking ModelTracker's (on its own thread).
#include <cstring>

#include "rigger/dds/conversions.hpp"
#include "rigger/dds/sequences.hpp"
#include "rigger/protocol/robot.hpp"
#include "vision_tracker_node.hpp"

namespace rigger::vision {

namespace {

/// Why `image` cannot be read as the camera's depth image, or nullptr.
const char* depth_problem(const rigger_vision_Image& image, std::size_t bytes, const CameraIntrinsics& camera) {
  if (dds::to_string(image.encoding) != "32FC1") return "encoding is not 32FC1";
  if (image.is_bigendian) return "big-endian floats";
  if (static_cast<int>(image.width) != camera.width_px || static_cast<int>(image.height) != camera.height_px)
    return "not the camera's size";
  if (image.step < image.width * sizeof(float) || image.step % sizeof(float) != 0) return "step is not whole floats";
  if (bytes != static_cast<std::uint64_t>(image.step) * image.height) return "data length is not step * height";
  for (double k : camera.distortion) {
    if (k != 0.0) return "the camera has lens distortion (the depth image must be undistorted)";
  }
  return nullptr;
}

}  // namespace

bool VisionTrackerNode::request_by_model(const std::string& object_id, Stamp fresh_after) {
  if (object_id.empty()) {
    ctx_.log->warn("TRACK_ONCE_MODEL dropped: it needs one object, not \"\" (every object)");
    return false;
  }
  if (!model_localizer_.has_model(object_id)) {
    ModelLocalization none;
    none.status = "NO_MODEL";
    none.detail = "'" + object_id + "' is no object of the cell with a STEP model (model.step)";
    publish_model(object_id, std::chrono::system_clock::now(), none);
    return true;
  }
  model_requests_[object_id] = {fresh_after, dds::EventLoop::Clock::now() + once_timeout_};
  ctx_.loop.after(once_timeout_, [this] { on_model_deadline(); });
  return true;
}

void VisionTrackerNode::on_model_deadline() {
  const auto now = dds::EventLoop::Clock::now();
  for (auto it = model_requests_.begin(); it != model_requests_.end();) {
    if (it->second.deadline > now) {
      ++it;
      continue;
    }
    ModelLocalization none;
    none.status = "NO_DEPTH";
    none.detail = "no depth image (rigger/camera/depth) within " +
                  std::to_string(std::chrono::duration<double>(once_timeout_).count()) + " s";
    ctx_.log->warn("track_once_model timed out object={}: no depth image", it->first);
    const std::string id = it->first;
    it = model_requests_.erase(it);
    publish_model(id, std::chrono::system_clock::now(), none);
  }
}

void VisionTrackerNode::on_entities() {
  entities_.take([this](const rigger_world_EntityState& e, const dds_sample_info_t&) {
    const std::string id = dds::to_string(e.entity_id);
    if (e.has_pose && dds::to_string(e.parent_frame) == frame_id_) {
      world_poses_[id] = dds::to_domain(e.pose.pose);
    } else {
      world_poses_.erase(id);
    }
  });
}

void VisionTrackerNode::on_robot_state() {
  robot_states_.take([this](const rigger_robot_RobotState& state, const dds_sample_info_t&) {
    if (!model_tracker_.any()) return;
    // The tool pose is in the robot's base frame: a cell entity (its pose in the world from the cell file).
    const std::string base = dds::to_string(state.header.frame_id);
    Eigen::Isometry3d pose_world_base = Eigen::Isometry3d::Identity();
    if (base != frame_id_) {
      if (cell_.find(base) == nullptr) {
        if (!robot_frame_warned_) {
          ctx_.log->warn("robot state in frame \"{}\", no entity of the cell: a held object is not followed with the "
                         "robot's tool", base);
        }
        robot_frame_warned_ = true;
        return;
      }
      pose_world_base = cell_.pose_root_entity(base);
    }
    model_tracker_.tool_pose(dds::to_domain(state.header.stamp), pose_world_base * dds::to_domain(state.tool_pose));
  });
}

bool VisionTrackerNode::track_by_model(const std::string& object_id) {
  if (object_id.empty() || !model_localizer_.has_model(object_id)) return false;
  std::string problem;
  const perception::Mesh* mesh = model_localizer_.mesh(object_id, problem);
  if (mesh == nullptr) {
    ModelLocalization none;
    none.status = "NO_MODEL";
    none.detail = problem;
    publish_model(object_id, std::chrono::system_clock::now(), none);
    return true;
  }
  const auto prior = world_poses_.find(object_id);
  model_tracker_.start(object_id, std::make_shared<const perception::Mesh>(*mesh),
                       prior != world_poses_.end() ? std::optional<Eigen::Isometry3d>(prior->second) : std::nullopt);
  ctx_.log->info("tracking object={} by its model from {}", object_id,
                 prior != world_poses_.end() ? "its pose in the world model" : "a search of the whole image");
  return true;
}

void VisionTrackerNode::on_depth() {
  depth_.take([this](const rigger_vision_Image& image, const dds_sample_info_t&) {
    const bool tracking = model_tracker_.any();
    if (model_requests_.empty() && !tracking) return;
    perception::DepthFrame frame;
    const char* problem = depth_frame(image, frame);
    const Stamp stamp = dds::to_domain(image.header.stamp);
    if (!model_requests_.empty()) localize_by_model(stamp, frame, problem);
    if (!tracking) return;
    if (problem != nullptr) {
      ctx_.log->warn("depth image not tracked in: {}", problem);
      return;
    }
    model_tracker_.submit(std::move(frame), stamp);
  });
}

const char* VisionTrackerNode::depth_frame(const rigger_vision_Image& image, perception::DepthFrame& frame) const {
  const CameraIntrinsics& camera = tracker_.config().camera;
  const auto data = dds::elements(image.data);
  const char* problem = depth_problem(image, data.size(), camera);
  if (problem != nullptr) return problem;
  // A copy: the localizer wants aligned floats, and the sample's buffer is returned after this call.
  frame.depth_m.create(static_cast<int>(image.height), static_cast<int>(image.width), CV_32FC1);
  for (int row = 0; row < frame.depth_m.rows; ++row) {
    std::memcpy(frame.depth_m.ptr(row), data.data() + static_cast<std::size_t>(row) * image.step,
                image.width * sizeof(float));
  }
  frame.intrinsics = {camera.fx_px, camera.fy_px, camera.cx_px, camera.cy_px};
  frame.pose_world_camera = tracker_.config().pose_world_camera;
  return nullptr;
}

void VisionTrackerNode::localize_by_model(Stamp stamp, const perception::DepthFrame& frame, const char* problem) {
  std::vector<std::string> due;  // the requests sent before this image was taken
  for (const auto& [id, request] : model_requests_) {
    if (stamp > request.fresh_after) due.push_back(id);
  }
  for (const std::string& id : due) {
    model_requests_.erase(id);
    ModelLocalization result;
    if (problem != nullptr) {
      result.status = "BAD_DEPTH";
      result.detail = std::string("depth image refused: ") + problem;
    } else {
      const auto prior = world_poses_.find(id);
      result = model_localizer_.localize(
          id, frame, prior != world_poses_.end() ? std::optional<Eigen::Isometry3d>(prior->second) : std::nullopt);
    }
    ctx_.log->info("track_once_model object={} status={} elapsed_ms={} prior={} detail=\"{}\"", id, result.status,
                   std::chrono::duration_cast<std::chrono::milliseconds>(result.result.elapsed).count(),
                   world_poses_.count(id) != 0, result.detail);
    publish_model(id, stamp, result);
  }
}

void VisionTrackerNode::publish_model(const std::string& object_id, Stamp stamp, const ModelLocalization& result) {
  rigger_vision_TrackedPose out{};
  out.header.stamp = dds::to_wire(stamp);
  out.header.frame_id = dds::wire_string(frame_id_);
  out.object_id = dds::wire_string(object_id);
  out.tracked = result.found();
  // Never a pose that did not pass the fit checks: a refused one is identity with quality 0.
  out.pose.pose = dds::to_wire(result.found() ? result.pose_world_object : Eigen::Isometry3d::Identity());
  out.quality = result.found() ? result.quality : 0.0;
  out.status = dds::wire_string(result.status);
  out.detail = dds::wire_string(result.detail);
  poses_.write(out);
}

}  // namespace rigger::vision
