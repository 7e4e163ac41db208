// One frame of the demo cell's camera (deploy/cell/simulated_cell.json, 1280 x 720) rendered by
// MujocoCamera (MuJoCo headless through EGL, the physics' model of the cell, models/cell.xml with the
// cell file's objects, at its reference pose), next to CameraRenderer (the boxes-and-markers rasteriser) on the same poses in the same
// run; and MujocoCamera again with lens distortion (k1 = -0.2), whose pinhole render is larger.
// Not a test. Figures: median of kFrames frames after one warm-up frame, wall time, milliseconds.
// `camera_bench DIR` also writes the frames to DIR (mujoco.png, mujoco_distorted.png, depth.png with
// 1 grey level per 2 cm, rasteriser.png) to look at.
//
// The markers sit on the bodies named as the cell file's objects: in the physics' model a body's
// frame is its object's frame.

#include "rigger/performance/results.hpp"
#include "rigger/sim/camera_renderer.hpp"
#include "rigger/sim/camera_scene.hpp"
#include "rigger/sim/cell_physics.hpp"
#include "rigger/sim/mujoco_camera.hpp"

#include <opencv2/imgcodecs.hpp>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <exception>
#include <functional>
#include <memory>
#include <string>
#include <vector>

namespace {

using namespace rigger;
using Clock = std::chrono::steady_clock;

constexpr int kFrames = 15;

double median_ms(const std::function<void()>& frame) {
  frame();  // warm-up: first-use allocations, shader compilation
  std::vector<double> ms;
  for (int i = 0; i < kFrames; ++i) {
    const auto start = Clock::now();
    frame();
    ms.push_back(std::chrono::duration<double, std::milli>(Clock::now() - start).count());
  }
  std::nth_element(ms.begin(), ms.begin() + kFrames / 2, ms.end());
  return ms[kFrames / 2];
}

std::vector<sim::ObjectPose> body_poses(const mjModel& model, const mjData& data,
                                        const std::vector<sim::BoxObject>& objects) {
  std::vector<sim::ObjectPose> poses;
  for (const sim::BoxObject& object : objects) {
    const int body = mj_name2id(&model, mjOBJ_BODY, object.id.c_str());
    if (body < 0) {
      continue;
    }
    Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
    pose.translation() = Eigen::Map<const Eigen::Vector3d>(data.xpos + 3 * body);
    pose.linear() = Eigen::Map<const Eigen::Matrix<double, 3, 3, Eigen::RowMajor>>(data.xmat + 9 * body);
    poses.push_back({object.id, pose});
  }
  return poses;
}

int run(const std::string& save_dir) {
  const sim::CameraScene scene = sim::load_camera_scene(RIGGER_DEMO_CELL_JSON);
  // The model as the physics generates it (the objects are not in models/cell.xml itself).
  const std::shared_ptr<const mjModel> model_copy =
      sim::CellPhysics(sim::load_cell_geometry(RIGGER_DEMO_CELL_JSON)).copy_model();
  const mjModel* model = model_copy.get();
  mjData* data = mj_makeData(model);
  mj_forward(model, data);
  const std::vector<sim::ObjectPose> poses = body_poses(*model, *data, scene.objects);

  sim::MujocoCameraSettings no_noise;  // both renderers without pixel noise: the same work
  no_noise.noise_stddev = 0.0;
  double gl_ms = 0;
  double gl_distorted_ms = 0;
  int markers = 0;
  cv::Size render_size;
  cv::Size distorted_render_size;
  {
    sim::MujocoCamera camera(*model, scene, no_noise);
    sim::CameraFrame frame;
    gl_ms = median_ms([&] { camera.render(*data, scene.pose_world_camera, poses, frame); });
    markers = frame.markers_drawn;
    if (!save_dir.empty()) {
      cv::imwrite(save_dir + "/mujoco.png", frame.image_mono8);
      cv::Mat depth_cm;
      frame.depth_m.convertTo(depth_cm, CV_8UC1, 50.0);  // NaN becomes 0
      cv::imwrite(save_dir + "/depth.png", depth_cm);
    }
    render_size = camera.render_size();
    std::printf("OpenGL renderer: %s\n", camera.gl_renderer());
  }
  {
    sim::CameraModel distorted = scene.camera;
    distorted.distortion = {-0.2, 0.05, 0.001, -0.001, 0.0};
    sim::MujocoCamera camera(*model, distorted, scene.objects, scene.dictionary, no_noise);
    sim::CameraFrame frame;
    gl_distorted_ms = median_ms([&] { camera.render(*data, scene.pose_world_camera, poses, frame); });
    distorted_render_size = camera.render_size();
    if (!save_dir.empty()) {
      cv::imwrite(save_dir + "/mujoco_distorted.png", frame.image_mono8);
    }
  }
  sim::RenderSettings settings;
  settings.noise_stddev = 0.0;
  sim::CameraRenderer renderer(scene, settings);
  cv::Mat image;
  const double raster_ms = median_ms([&] { renderer.render(scene.pose_world_camera, poses, image); });
  if (!save_dir.empty()) {
    cv::imwrite(save_dir + "/rasteriser.png", image);
  }
  mj_deleteData(data);

  std::printf("demo cell %d x %d, %zu objects, %d markers drawn\n", scene.camera.width_px, scene.camera.height_px,
              poses.size(), markers);
  std::printf("MujocoCamera frame (render %d x %d)       %7.1f ms\n", render_size.width, render_size.height, gl_ms);
  std::printf("MujocoCamera frame, k1 = -0.2 (render %d x %d) %7.1f ms\n", distorted_render_size.width,
              distorted_render_size.height, gl_distorted_ms);
  std::printf("CameraRenderer frame                      %7.1f ms\n", raster_ms);

  performance::Report report("camera_bench", "Simulated camera: one frame of the demo cell, MuJoCo vs rasteriser");
  report.add({"MujocoCamera frame (grey + depth)", gl_ms, "ms", "CameraRenderer frame, same poses", raster_ms});
  report.add({"MujocoCamera frame with k1 = -0.2 distortion", gl_distorted_ms, "ms", "CameraRenderer frame, same poses",
              raster_ms});
  report.save();
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  try {
    return run(argc > 1 ? argv[1] : "");
  } catch (const std::exception& e) {
    std::fprintf(stderr, "camera_bench: %s\n", e.what());
    return 1;
  }
}
