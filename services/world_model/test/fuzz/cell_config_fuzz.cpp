// libFuzzer target: the cell-configuration loader must answer any input with a config or a
// CellConfigError, never a crash, a hang or another exception.
#include <cstddef>
#include <cstdint>
#include <string_view>

#include "world_cell_config.hpp"
#include "world_frame_tree.hpp"
#include "world_store.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  try {
    const auto config = rigger::world::parse_cell_config(text, "fuzz-input.json");
    // A valid configuration must also build a store whose frame tree answers for every entity.
    const auto store = rigger::world::WorldStore::from_config(config, rigger::world::Stamp(std::chrono::seconds(1)));
    const auto& first = store.entities().begin()->first;
    for (const auto& [id, entity] : store.entities()) {
      const auto result = rigger::world::pose_in_frame(store.entities(), id, first);
      if (result.status == rigger::world::QueryStatus::kFrameCycle) __builtin_trap();  // the loader must refuse cycles
    }
  } catch (const rigger::world::CellConfigError&) {
    // Expected for malformed input.
  }
  return 0;
}
