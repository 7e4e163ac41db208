#pragma once
// Shared by the decoder fuzzers: turn libFuzzer bytes into the fields of a wire sample, often enough
// picking plausible values (known ids, unit quaternions) that the fuzzer gets past the first checks.

#include <cstdint>
#include <cstring>
#include <string>

#include <fuzzer/FuzzedDataProvider.h>

#include "world_cell_config.hpp"
#include "world_store.hpp"

namespace rigger::world::fuzz {

// A double: any bit pattern (NaN, infinities, denormals) or a plausible number.
inline double any_double(FuzzedDataProvider& in) {
  if (in.ConsumeBool()) {
    const std::uint64_t bits = in.ConsumeIntegral<std::uint64_t>();
    double d;
    std::memcpy(&d, &bits, sizeof d);
    return d;
  }
  static const double kPlausible[] = {0.0, 1.0, -1.0, 0.5, 0.70710678118654752, 1e-7, 3.55, 1e300};
  return in.PickValueInArray(kPlausible);
}

// An id: a known entity or feature id, or any string.
inline std::string any_id(FuzzedDataProvider& in) {
  static const char* kIds[] = {"world", "crane", "robot", "gripper", "camera", "load", "target",
                               "grasp_side", "pre_grasp", "h1", "h3", "rope_attachment", ""};
  if (in.ConsumeBool()) return kIds[in.ConsumeIntegralInRange<std::size_t>(0, sizeof(kIds) / sizeof(kIds[0]) - 1)];
  return in.ConsumeRandomLengthString(100);
}

// The fixture cell as a store, built once.
inline const WorldStore& fixture_store() {
  static const WorldStore store = WorldStore::from_config(
      load_cell_config(std::string(RIGGER_SOURCE_DIR) + "/services/world_model/test/data/cell_fixture.json"),
      Stamp(std::chrono::seconds(1000)));
  return store;
}

}  // namespace rigger::world::fuzz
