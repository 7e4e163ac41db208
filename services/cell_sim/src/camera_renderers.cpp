#include "camera_renderers.hpp"

#include <algorithm>
#include <cmath>
#include <optional>
#include <stdexcept>
#include <utility>

namespace rigger::cell_sim {
namespace {

class RasterRenderer final : public FrameRenderer {
 public:
  RasterRenderer(const sim::CameraScene& scene, sim::RenderSettings settings)
      : pose_world_camera_(scene.pose_world_camera), renderer_(scene, std::move(settings)) {}

  void render(const CameraSnapshot& snapshot, const CameraDemand& /*demand*/, CameraImages& images) override {
    renderer_.render(pose_world_camera_, snapshot.poses, images.image_mono8);
    images.depth_m.release();
  }

 private:
  Eigen::Isometry3d pose_world_camera_;
  sim::CameraRenderer renderer_;
};

struct DataDeleter {
  void operator()(mjData* d) const { mj_deleteData(d); }
};

class MujocoRenderer final : public FrameRenderer {
 public:
  MujocoRenderer(std::shared_ptr<const mjModel> model, const sim::CameraScene& scene,
                 sim::MujocoCameraSettings settings)
      : model_(std::move(model)),
        data_(mj_makeData(model_.get())),
        pose_world_camera_(scene.pose_world_camera),
        camera_(*model_, scene, settings) {
    if (!data_) throw std::bad_alloc();
    mj_kinematics(model_.get(), data_.get());
  }

  void render(const CameraSnapshot& snapshot, const CameraDemand& demand, CameraImages& images) override {
    // A scene that has not moved since the last frame (and needs no depth that frame lacked) is not
    // rendered again: most of a cell's time is spent waiting, and a render costs tens of ms.
    if (still(snapshot) && (!demand.depth || !frame_.depth_m.empty()) && camera_.repeat(frame_)) {
      publish(demand, images);
      return;
    }
    last_ = snapshot;
    const mjModel& m = *model_;
    mjData& d = *data_;
    // A state of another model (none: a snapshot without positions) leaves the bodies where they were.
    const sim::KinematicState& s = snapshot.state;
    if (s.qpos.size() == static_cast<std::size_t>(m.nq) &&
        s.mocap_pos.size() == static_cast<std::size_t>(3 * m.nmocap) &&
        s.mocap_quat.size() == static_cast<std::size_t>(4 * m.nmocap)) {
      std::copy(s.qpos.begin(), s.qpos.end(), d.qpos);
      std::copy(s.mocap_pos.begin(), s.mocap_pos.end(), d.mocap_pos);
      std::copy(s.mocap_quat.begin(), s.mocap_quat.end(), d.mocap_quat);
      // Positions only: body and geom poses, then what the lights and cameras follow.
      mj_kinematics(&m, &d);
      mj_comPos(&m, &d);
      mj_camlight(&m, &d);
    }
    camera_.render(d, pose_world_camera_, snapshot.poses, frame_, demand.depth);
    publish(demand, images);
  }

 private:
  void publish(const CameraDemand& demand, CameraImages& images) const {
    images.image_mono8 = frame_.image_mono8;
    if (demand.depth) {
      images.depth_m = frame_.depth_m;
    } else {
      images.depth_m.release();
    }
  }

  /// Whether `snapshot` poses everything as the last rendered one did, to far below a pixel.
  bool still(const CameraSnapshot& snapshot) const {
    constexpr double kStill = 1e-7;  // metres, radians and quaternion components
    const auto same = [](const std::vector<double>& a, const std::vector<double>& b) {
      if (a.size() != b.size()) return false;
      for (std::size_t i = 0; i < a.size(); ++i) {
        if (!(std::abs(a[i] - b[i]) <= kStill)) return false;
      }
      return true;
    };
    if (!last_ || last_->poses.size() != snapshot.poses.size()) return false;
    for (std::size_t i = 0; i < snapshot.poses.size(); ++i) {
      const sim::ObjectPose& a = last_->poses[i];
      const sim::ObjectPose& b = snapshot.poses[i];
      if (a.object_id != b.object_id || !a.pose_world_object.isApprox(b.pose_world_object, kStill)) return false;
    }
    return same(last_->state.qpos, snapshot.state.qpos) && same(last_->state.mocap_pos, snapshot.state.mocap_pos) &&
           same(last_->state.mocap_quat, snapshot.state.mocap_quat);
  }

  std::shared_ptr<const mjModel> model_;
  std::unique_ptr<mjData, DataDeleter> data_;
  Eigen::Isometry3d pose_world_camera_;
  sim::MujocoCamera camera_;  // after the model it renders: destroyed before it
  sim::CameraFrame frame_;
  std::optional<CameraSnapshot> last_;  // what frame_ shows
};

}  // namespace

std::unique_ptr<FrameRenderer> make_raster_renderer(const sim::CameraScene& scene, sim::RenderSettings settings) {
  return std::make_unique<RasterRenderer>(scene, std::move(settings));
}

std::unique_ptr<FrameRenderer> make_mujoco_renderer(std::shared_ptr<const mjModel> model, const sim::CameraScene& scene,
                                                    sim::MujocoCameraSettings settings) {
  if (!model) throw std::invalid_argument("camera: no model to render");
  return std::make_unique<MujocoRenderer>(std::move(model), scene, settings);
}

CameraRendererKind resolve_renderer(CameraRendererKind configured, const sim::CellGeometry& geometry,
                                    const sim::CameraModel& camera) {
  if (configured != CameraRendererKind::kAuto) return configured;
  const bool boxes_only = std::all_of(geometry.objects.begin(), geometry.objects.end(),
                                      [](const sim::ObjectGeometry& object) { return object.box_size_m.has_value(); });
  const bool pinhole = std::all_of(camera.distortion.begin(), camera.distortion.end(), [](double k) { return k == 0.0; });
  return boxes_only && pinhole ? CameraRendererKind::kRaster : CameraRendererKind::kMujoco;
}

RendererFactory renderer_factory(CameraRendererKind kind, const CellSimConfig& config, const sim::CameraScene& scene,
                                 std::shared_ptr<const mjModel> model) {
  if (kind == CameraRendererKind::kAuto) throw std::logic_error("renderer_factory: resolve `auto` first");
  if (kind == CameraRendererKind::kRaster) {
    sim::RenderSettings settings;
    settings.noise_stddev = config.camera_noise_stddev;
    settings.blur_sigma_px = config.camera_blur_sigma_px;
    settings.albedo = {{"load", 0.62}, {"target", 0.38}};  // the demo cell's two boxes apart in grey
    return [scene, settings] { return make_raster_renderer(scene, settings); };
  }
  sim::MujocoCameraSettings settings;
  settings.noise_stddev = config.camera_noise_stddev;
  settings.depth_noise = config.camera_depth_noise;
  return [scene, settings, model = std::move(model)] { return make_mujoco_renderer(model, scene, settings); };
}

}  // namespace rigger::cell_sim
