#include "rigger/sim/mujoco_camera.hpp"

#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

#include "lens_map.hpp"
#include "marker_decals.hpp"

namespace rigger::sim {
namespace {

bool finite(const Eigen::Isometry3d& pose) {
  return pose.matrix().allFinite();
}

}  // namespace

MujocoCamera::MujocoCamera(const mjModel& model, const CameraModel& camera, std::vector<BoxObject> objects,
                           int dictionary, MujocoCameraSettings settings)
    : model_(&model),
      camera_(camera),
      settings_(settings),
      noise_(settings.noise_stddev.value_or(camera.noise_stddev), settings.seed),
      depth_noise_(camera, settings.depth_noise, settings.seed + 1) {
  if (settings_.max_render_px < 16 || settings_.max_render_px > 16384) {
    throw std::invalid_argument("mujoco camera: max_render_px must be within 16..16384");
  }
  if (!(noise_.stddev() >= 0.0)) {
    throw std::invalid_argument("mujoco camera: noise_stddev must be >= 0");
  }
  for (const BoxObject& object : objects) {
    object_ids_.push_back(object.id);
  }
  lens_ = std::make_unique<detail::LensMap>(camera_, settings_.max_render_px);
  decals_ = std::make_unique<detail::MarkerDecals>(std::move(objects), dictionary, settings_.marker_white,
                                                   settings_.marker_black);
  const detail::PinholeRender& render = lens_->render();

  // mjr_makeContext sizes the offscreen buffer from the model's vis.global: hand it a shallow
  // copy with this camera's size rather than change the caller's model (it only reads the copy).
  // No multisampling: the multisampled depth buffer resolves to one sample off the pixel centre
  // (a millimetre on a plate tilted 30 degrees at 2.5 m). Mesh outlines alias; the markers, whose
  // edges the tracker measures, are antialiased by their own sampling.
  mjModel sized = model;
  sized.vis.global.offwidth = render.width_px;
  sized.vis.global.offheight = render.height_px;
  sized.vis.quality.offsamples = 0;
  mjr_defaultContext(&context_);
  mjr_makeContext(&sized, &context_, mjFONTSCALE_100);
  if (context_.offWidth < render.width_px || context_.offHeight < render.height_px) {
    mjr_freeContext(&context_);
    throw GlUnavailableError("mujoco camera: OpenGL gave an offscreen buffer of " + std::to_string(context_.offWidth) +
                             " x " + std::to_string(context_.offHeight) + ", the render needs " +
                             std::to_string(render.width_px) + " x " + std::to_string(render.height_px));
  }
  mjr_setBuffer(mjFB_OFFSCREEN, &context_);

  mjv_defaultScene(&scene_);
  mjv_makeScene(&model, &scene_, std::max(1000, 2 * model.ngeom + 200));
  // A camera sees the bodies, not the modelling aids: no sites, joints, frames or labels (the
  // default option already hides the latter). No skybox, so that the background has no depth.
  mjv_defaultOption(&option_);
  std::fill(std::begin(option_.sitegroup), std::end(option_.sitegroup), mjtByte{0});
  scene_.flags[mjRND_SKYBOX] = 0;
  mjv_defaultFreeCamera(&model, &free_camera_);

  render_rgb_.create(render.height_px, render.width_px, CV_8UC3);
  render_depth_.create(render.height_px, render.width_px, CV_32FC1);
}

namespace {
// The markers MuJoCo's render carries: the boxes', those of objects given by their STEP model alone and
// the calibration boards'.
std::vector<BoxObject> marked_objects(const CameraScene& scene) {
  std::vector<BoxObject> objects = scene.objects;
  objects.insert(objects.end(), scene.mesh_objects.begin(), scene.mesh_objects.end());
  objects.insert(objects.end(), scene.boards.begin(), scene.boards.end());
  return objects;
}
}  // namespace

MujocoCamera::MujocoCamera(const mjModel& model, const CameraScene& scene, MujocoCameraSettings settings)
    : MujocoCamera(model, scene.camera, marked_objects(scene), scene.dictionary, settings) {}

MujocoCamera::~MujocoCamera() {
  mjv_freeScene(&scene_);  // CPU memory only
  try {
    gl_.make_current();
  } catch (const GlUnavailableError&) {
    return;  // the GL objects die with the context
  }
  mjr_freeContext(&context_);
}

cv::Size MujocoCamera::render_size() const {
  return {lens_->render().width_px, lens_->render().height_px};
}

double MujocoCamera::render_focal_px() const {
  return lens_->render().f_px;
}

RenderStatus MujocoCamera::render(mjData& data, const Eigen::Isometry3d& pose_world_camera,
                                  const std::vector<ObjectPose>& poses, CameraFrame& frame, bool depth) {
  if (!finite(pose_world_camera)) {
    return RenderStatus::kInvalidPose;
  }
  RenderStatus status = RenderStatus::kOk;
  for (const ObjectPose& pose : poses) {
    if (!finite(pose.pose_world_object)) {
      return RenderStatus::kInvalidPose;
    }
    if (std::find(object_ids_.begin(), object_ids_.end(), pose.object_id) == object_ids_.end()) {
      status = RenderStatus::kUnknownObject;
    }
  }
  try {
    gl_.make_current();
  } catch (const GlUnavailableError&) {
    return RenderStatus::kGlError;
  }
  const detail::PinholeRender& render = lens_->render();
  mjv_updateScene(model_, &data, &option_, nullptr, &free_camera_, mjCAT_ALL, &scene_);

  // Replace the free camera (which cannot roll) by the optical frame: OpenGL looks along -z with y
  // up, i.e. along the optical z with the optical -y up. The frustum spans the render's pixels
  // (edges at +-size/2 from the centred principal point) at MuJoCo's near and far planes.
  const Eigen::Vector3d position = pose_world_camera.translation();
  const Eigen::Vector3d forward = pose_world_camera.linear().col(2);
  const Eigen::Vector3d up = -pose_world_camera.linear().col(1);
  const float near_m = scene_.camera[0].frustum_near;
  const float far_m = scene_.camera[0].frustum_far;
  for (mjvGLCamera& eye : scene_.camera) {
    for (int k = 0; k < 3; ++k) {
      eye.pos[k] = static_cast<float>(position[k]);
      eye.forward[k] = static_cast<float>(forward[k]);
      eye.up[k] = static_cast<float>(up[k]);
    }
    eye.frustum_center = 0.0F;
    eye.frustum_top = static_cast<float>(near_m * 0.5 * render.height_px / render.f_px);
    eye.frustum_bottom = -eye.frustum_top;
  }
  // The headlight follows the free camera; move it to this one.
  for (int i = 0; i < scene_.nlight; ++i) {
    mjvLight& light = scene_.lights[i];
    if (light.headlight != 0) {
      for (int k = 0; k < 3; ++k) {
        light.pos[k] = static_cast<float>(position[k]);
        light.dir[k] = static_cast<float>(forward[k]);
      }
    }
  }

  const mjrRect viewport{0, 0, render.width_px, render.height_px};
  mjr_render(viewport, &scene_, &context_);
  mjr_readPixels(render_rgb_.ptr<unsigned char>(), render_depth_.ptr<float>(), viewport, &context_);

  const detail::DepthScale depth_scale{near_m, far_m};
  frame.markers_drawn =
      decals_->draw(*model_, data, render, depth_scale, pose_world_camera, poses, render_depth_, render_rgb_);

  if (settings_.colour) {
    lens_->remap_image(render_rgb_, frame.image_rgb8, cv::Scalar::all(0));
  } else {
    frame.image_rgb8.release();
  }
  cv::cvtColor(render_rgb_, render_grey_, cv::COLOR_RGB2GRAY);
  lens_->remap_image(render_grey_, clean_mono8_, cv::Scalar::all(0));
  clean_mono8_.copyTo(frame.image_mono8);
  noise_.add(frame.image_mono8);

  if (depth) {
    lens_->remap_depth(render_depth_, depth_scale, frame.depth_m);
    depth_noise_.apply(frame.depth_m);
  } else {
    frame.depth_m.release();
  }
  return status;
}

bool MujocoCamera::repeat(CameraFrame& frame) {
  if (clean_mono8_.empty()) return false;
  clean_mono8_.copyTo(frame.image_mono8);
  noise_.add(frame.image_mono8);
  return true;
}

}  // namespace rigger::sim
