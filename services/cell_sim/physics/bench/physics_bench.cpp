// Speed of the cell physics (on demand, not a test): steps per second and real-time factor of
// CellPhysics in typical situations, next to the floor measured in the same run: a bare mj_step
// on the same MJCF with no controllers.  Rates are per CPU second (the machine is shared); on an
// idle machine the wall-clock rate is the same.
//
//   build/bench/cell_sim_physics_bench [--benchmark_filter=...]

#include <benchmark/benchmark.h>
#include <mujoco/mujoco.h>

#include <array>
#include <cmath>
#include <memory>
#include <string>

#include "rigger/sim/cell_physics.hpp"
#include "rigger/sim/pose_math.hpp"

namespace rigger::sim {
namespace {

using namespace std::chrono_literals;

CellGeometry bench_cell() {
  return load_cell_geometry(std::string(RIGGER_SOURCE_DIR) + "/deploy/cell/simulated_cell.json");
}

void report(benchmark::State& state, double timestep_s) {
  state.SetItemsProcessed(state.iterations());
  state.counters["steps_per_s"] =
      benchmark::Counter(static_cast<double>(state.iterations()), benchmark::Counter::kIsRate);
  state.counters["real_time_factor"] = benchmark::Counter(
      static_cast<double>(state.iterations()) * timestep_s, benchmark::Counter::kIsRate);
}

// Floor: MuJoCo alone on the same model with gravity off, so nothing moves and nothing touches:
// the cost of a bare mj_step on this model, without controllers, contacts or sensors' users.
void BM_BareMujocoStep(benchmark::State& state) {
  std::array<char, 1024> error{};
  std::unique_ptr<mjModel, void (*)(mjModel*)> model(
      mj_loadXML(default_model_path().c_str(), nullptr, error.data(), error.size()),
      mj_deleteModel);
  if (!model) {
    state.SkipWithError(error.data());
    return;
  }
  model->opt.disableflags |= mjDSBL_GRAVITY;
  std::unique_ptr<mjData, void (*)(mjData*)> data(mj_makeData(model.get()), mj_deleteData);
  for (auto _ : state) {
    mj_step(model.get(), data.get());
  }
  report(state, model->opt.timestep);
}
BENCHMARK(BM_BareMujocoStep);

// The cell at rest: crane holding, load hanging, arm holding its pose.
void BM_CellPhysicsIdle(benchmark::State& state) {
  CellPhysics physics(bench_cell());
  for (auto _ : state) {
    physics.step(1ms);
  }
  report(state, 1e-3);
}
BENCHMARK(BM_CellPhysicsIdle);

// Busy: the crane travelling, the arm in resolved-rate twist mode (Jacobian and solver every
// step), the load swinging.
void BM_CellPhysicsCraneAndTwist(benchmark::State& state) {
  CellPhysics physics(bench_cell());
  physics.set_crane_velocity({0.2, 0.1, 0.0});
  Twist twist;
  twist.linear_mps = Eigen::Vector3d(0.0, 0.02, 0.0);
  int step = 0;
  for (auto _ : state) {
    if (step++ % 10 == 0) {
      physics.set_tool_twist(twist);
      twist.linear_mps.y() = -twist.linear_mps.y();  // wobble so it never runs out of reach
    }
    physics.step(1ms);
  }
  report(state, 1e-3);
}
BENCHMARK(BM_CellPhysicsCraneAndTwist);

// Holding: the magnet holds the load, the robot guides it while the crane travels (the paper's
// collaborative transport): contact, magnet forces and both sensors every step.
void BM_CellPhysicsHoldingLoad(benchmark::State& state) {
  CellPhysics physics(bench_cell());
  const CellGeometry& cell = physics.geometry();
  const Eigen::Isometry3d base_from_world = physics.pose_world_robot_base().inverse();
  physics.move_tool(
      base_from_world * physics.pose_world_load() * cell.load.approach_waypoints.front().pose_entity_feature, 0.5);
  physics.step(3s);
  physics.set_gripper_energized(true);
  physics.move_tool(base_from_world * physics.pose_world_load() * *cell.grasp_frame("grasp_side"),
                    0.2);
  physics.step(3s);
  if (!physics.gripper_state().holding) {
    state.SkipWithError("the gripper did not grip the load");
    return;
  }
  physics.set_crane_velocity({0.0, 0.02, 0.0});
  Twist twist;
  twist.linear_mps = Eigen::Vector3d(0.0, 0.02, 0.0);
  int step = 0;
  for (auto _ : state) {
    if (step++ % 10 == 0) {
      physics.set_tool_twist(twist);
    }
    if (step % 4000 == 0) {  // turn round before running out of reach
      twist.linear_mps.y() = -twist.linear_mps.y();
      physics.set_crane_velocity({0.0, twist.linear_mps.y(), 0.0});
    }
    physics.step(1ms);
  }
  report(state, 1e-3);
}
BENCHMARK(BM_CellPhysicsHoldingLoad);

void BM_InverseKinematics(benchmark::State& state) {
  CellPhysics physics(bench_cell());
  const Eigen::Isometry3d goal = physics.pose_world_robot_base().inverse() *
                                 physics.pose_world_load() *
                                 *physics.geometry().grasp_frame("grasp_side");
  for (auto _ : state) {
    benchmark::DoNotOptimize(physics.solve_ik(goal));
  }
}
BENCHMARK(BM_InverseKinematics);

}  // namespace
}  // namespace rigger::sim

BENCHMARK_MAIN();
