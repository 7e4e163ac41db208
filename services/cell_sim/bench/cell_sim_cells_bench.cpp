// The simulated cell's two costs with the demo cell (deploy/cell/simulated_cell.json: four boxes) and
// with the generated 6-object cell (rigger_generated_cell: STEP table, L bracket, flange, two STEP parts,
// one box), same run: one physics step (CellPhysics::step of 1 ms, the cell at rest after settling) and
// one camera frame at the cell file's 1280 x 720, rendered as the cell_sim process renders it (the
// camera thread's FrameRenderers: MuJoCo through EGL on a copy of the physics' model posed by its
// joint positions, and the boxes-and-markers rasteriser). Not a test. Figures: medians, wall time.
//   build/bench/cell_sim_cells_bench

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <exception>
#include <functional>
#include <string>
#include <vector>

#include "camera_renderers.hpp"
#include "cell_sim_config.hpp"
#include "rigger/performance/results.hpp"
#include "rigger/sim/cell_physics.hpp"
#include "rigger/sim/generated_cell.hpp"

namespace {

using namespace rigger;
using Clock = std::chrono::steady_clock;

constexpr int kFrames = 15;
constexpr int kStepBatches = 21;
constexpr int kStepsPerBatch = 200;

double median(std::vector<double> values) {
  std::nth_element(values.begin(), values.begin() + values.size() / 2, values.end());
  return values[values.size() / 2];
}

struct CellFigures {
  double step_us = 0;
  double mujoco_ms = 0;
  double raster_ms = 0;
  int bodies = 0;
};

CellFigures measure(const std::filesystem::path& cell_file) {
  CellFigures f;
  sim::CellPhysics physics(sim::load_cell_geometry(cell_file));
  physics.step(std::chrono::milliseconds(500));  // settle: parts on their tables, the load hanging
  std::vector<double> us;
  for (int b = 0; b < kStepBatches; ++b) {
    const auto start = Clock::now();
    for (int i = 0; i < kStepsPerBatch; ++i) physics.step(std::chrono::milliseconds(1));
    us.push_back(std::chrono::duration<double, std::micro>(Clock::now() - start).count() / kStepsPerBatch);
  }
  f.step_us = median(us);
  f.bodies = static_cast<int>(physics.object_bodies().size());

  const sim::CameraScene scene = sim::load_camera_scene(cell_file);
  cell_sim::CameraSnapshot snapshot;
  for (const sim::BoxObject& object : scene.objects) {
    snapshot.poses.push_back({object.id, *physics.pose_world_object(object.id)});
  }
  physics.copy_kinematic_state(snapshot.state);
  // Every frame a moving scene (the first object 1 um one way or the other): a renderer that re-sends
  // the frame of a still scene must render each of these.
  const auto frame_ms = [&](cell_sim::FrameRenderer& renderer) {
    cell_sim::CameraImages images;
    const cell_sim::CameraDemand both;  // the image and the depth
    renderer.render(snapshot, both, images);  // warm-up: first-use allocations, shader compilation
    std::vector<double> ms;
    for (int i = 0; i < kFrames; ++i) {
      cell_sim::CameraSnapshot moved = snapshot;
      if (!moved.poses.empty()) moved.poses.front().pose_world_object.translation().x() += (i % 2 ? 1e-6 : -1e-6);
      const auto start = Clock::now();
      renderer.render(moved, both, images);
      ms.push_back(std::chrono::duration<double, std::milli>(Clock::now() - start).count());
    }
    return median(ms);
  };
  sim::MujocoCameraSettings gl;  // both renderers without pixel noise: the same work
  gl.noise_stddev = 0.0;
  f.mujoco_ms = frame_ms(*cell_sim::make_mujoco_renderer(physics.copy_model(), scene, gl));
  sim::RenderSettings raster;
  raster.noise_stddev = 0.0;
  f.raster_ms = frame_ms(*cell_sim::make_raster_renderer(scene, raster));
  return f;
}

int run() {
  const CellFigures demo = measure(cell_sim::default_cell_file());
  const sim::GeneratedCell generated_files;
  const CellFigures generated = measure(generated_files.write());
  for (const auto& [name, f] : {std::pair{"demo cell", demo}, std::pair{"generated cell", generated}}) {
    std::printf("%-15s %d objects: physics step %6.1f us, camera frame MuJoCo %6.1f ms, rasteriser %5.1f ms\n", name,
                f.bodies, f.step_us, f.mujoco_ms, f.raster_ms);
  }
  performance::Report report("cell_sim_cells_bench",
                             "Physics step and camera frame (1280 x 720), demo cell vs generated 6-object cell");
  report.add({"physics step, generated 6-object cell", generated.step_us, "us", "demo cell (4 boxes)", demo.step_us});
  report.add({"MuJoCo camera frame, generated cell", generated.mujoco_ms, "ms", "demo cell", demo.mujoco_ms});
  report.add({"rasteriser camera frame, generated cell", generated.raster_ms, "ms", "demo cell", demo.raster_ms});
  report.add({"MuJoCo camera frame, demo cell", demo.mujoco_ms, "ms", "rasteriser, same poses", demo.raster_ms});
  return performance::save_for_main(report);
}

}  // namespace

int main() {
  try {
    return run();
  } catch (const std::exception& e) {
    std::fprintf(stderr, "cell_sim_cells_bench: %s\n", e.what());
    return 1;
  }
}
