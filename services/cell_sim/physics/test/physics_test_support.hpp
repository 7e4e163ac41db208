#pragma once
// Shared helpers of the MuJoCo-backed physics tests.

#include <algorithm>
#include <chrono>
#include <cmath>
#include <string>

#include "rigger/sim/cell_physics.hpp"

namespace rigger::sim::test_support {

using namespace std::chrono_literals;

/// The shared cell configuration (deploy/cell/simulated_cell.json), the one the deployment uses.
inline std::string reachable_cell_path() { return std::string(RIGGER_SOURCE_DIR) + "/deploy/cell/simulated_cell.json"; }

inline CellGeometry reachable_cell() { return load_cell_geometry(reachable_cell_path()); }

inline double seconds(std::chrono::nanoseconds duration) {
  return std::chrono::duration<double>(duration).count();
}

/// Steps in `step` increments until `done()` or `timeout` of simulated time; returns done().
template <typename Predicate>
bool run_until(CellPhysics& physics, Predicate done, std::chrono::nanoseconds timeout,
               std::chrono::nanoseconds step = 10ms) {
  const std::chrono::nanoseconds end = physics.sim_time() + timeout;
  while (!done()) {
    if (physics.sim_time() >= end) {
      return false;
    }
    physics.step(step);
  }
  return true;
}

/// A load feature (tool frame in the load frame) in the robot's base frame, where the load is now.
inline Eigen::Isometry3d feature_in_base(const CellPhysics& physics,
                                         const Eigen::Isometry3d& pose_load_feature) {
  return physics.pose_world_robot_base().inverse() * physics.pose_world_load() * pose_load_feature;
}

/// Hoists (velocity commands, as the PLC would send) until the drum has paid out `rope_m`.
inline bool hoist_to(CellPhysics& physics, double rope_m) {
  const bool reached = run_until(
      physics,
      [&] {
        const double error = rope_m - physics.crane_state().position_m.z();
        physics.set_crane_velocity({0.0, 0.0, std::clamp(2.0 * error, -0.2, 0.2)});
        return std::abs(error) < 5e-4;
      },
      30s, 1ms);
  physics.set_crane_velocity(Eigen::Vector3d::Zero());
  return reached;
}

/// Runs the motion last commanded to its end; true when it was Reached.
inline bool finish_motion(CellPhysics& physics, std::chrono::nanoseconds timeout = 20s) {
  run_until(
      physics, [&] { return physics.robot_state().motion.status != MotionStatus::Running; },
      timeout);
  return physics.robot_state().motion.status == MotionStatus::Reached;
}

}  // namespace rigger::sim::test_support
