#pragma once
// Fixed crane numbers for tests, benchmarks and fuzzers of the crane protocol's users.

#include "rigger/crane_protocol/register_map.hpp"

namespace rigger::crane::testing {

/// The limits of the simulated cell's crane as of deploy/cell/simulated_cell.json (bridge
/// 0..8 m, trolley 0..5 m, hook height 0.7..4.0 m, 0.5/0.5/0.2 m/s, 0.5/0.5/0.3 m/s^2, 3200 kg),
/// spelled out so that tests do not change meaning when the cell file does.
inline CraneLimits reference_limits() {
  CraneLimits limits;
  limits.position_min_m = {0.0, 0.0, 0.7};
  limits.position_max_m = {8.0, 5.0, 4.0};
  limits.max_speed_mps = {0.5, 0.5, 0.2};
  limits.max_accel_mps2 = {0.5, 0.5, 0.3};
  limits.rated_load_kg = 3200;
  return limits;
}

}  // namespace rigger::crane::testing
