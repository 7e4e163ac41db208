#pragma once
/// @file
/// The two renderers of the cell_sim camera (setting `camera/renderer`; `auto` picks one by the cell):
/// - `mujoco`: MuJoCo's OpenGL renderer, headless through EGL (MujocoCamera): what the physics model
///   holds (meshes and boxes, robot, crane), lit and shaded, with lens distortion and a depth image.
///   It renders its own copy of the model, posed by the physics' joint positions of each frame.
/// - `raster`: the boxes-and-markers rasteriser (CameraRenderer): the cell file's box objects only,
///   no distortion, no depth; cheap, for box-only cells.
/// Both are FrameRenderers for the CameraWorker; make them on the camera thread.

#include <memory>

#include "camera_worker.hpp"
#include "cell_sim_config.hpp"
#include "rigger/sim/cell_geometry.hpp"
#include "rigger/sim/mujoco_camera.hpp"

namespace rigger::cell_sim {

/// The rasteriser over the scene's box objects. @throws std::invalid_argument (bad scene or settings).
std::unique_ptr<FrameRenderer> make_raster_renderer(const sim::CameraScene& scene, sim::RenderSettings settings);

/// MuJoCo's renderer over `model` (a copy no other thread uses: CellPhysics::copy_model), with its
/// own EGL context, current on the calling thread. Each frame sets the snapshot's joint and mocap
/// positions on its own mjData and runs the kinematics.
/// @throws sim::GlUnavailableError without EGL or OpenGL; std::invalid_argument for a bad camera.
std::unique_ptr<FrameRenderer> make_mujoco_renderer(std::shared_ptr<const mjModel> model, const sim::CameraScene& scene,
                                                    sim::MujocoCameraSettings settings);

/// The renderer `auto` stands for: the rasteriser when every object of the cell is a box and the lens
/// has no distortion (all it draws), MuJoCo's otherwise; any other kind as it is.
CameraRendererKind resolve_renderer(CameraRendererKind configured, const sim::CellGeometry& geometry,
                                    const sim::CameraModel& camera);

/// The factory of renderer `kind` (resolved: not kAuto) with the configured noise (and, for the
/// rasteriser, blur and the demo cell's albedos). `model`: the physics' copy, for `mujoco` only.
RendererFactory renderer_factory(CameraRendererKind kind, const CellSimConfig& config, const sim::CameraScene& scene,
                                 std::shared_ptr<const mjModel> model);

}  // namespace rigger::cell_sim
