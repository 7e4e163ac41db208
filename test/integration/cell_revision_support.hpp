#pragma once
// Shared by the integration tests that drive cell_sim's cell revisions without a world model
// (generated_cell_test.cpp, cell_sim_process_test.cpp): a revision written on rigger/world/cell, and what the
// follower announces in the service state.
#include <chrono>
#include <cstdint>
#include <string>

#include <nlohmann/json.hpp>

#include "rigger/dds/pubsub.hpp"
#include "rigger/protocol/world.hpp"
#include "rigger/testing/cell.hpp"
#include "rigger/world_protocol/cell_protocol.hpp"

namespace rigger::testing {

/// Writes `document` on rigger/world/cell as revision `number` (changes against number - 1), as the world
/// model publishes a revision it accepted. Returns the write's return code.
inline dds_return_t publish_cell_revision(const dds::Writer<rigger_world_CellRevision>& writer, std::uint64_t number,
                                          const nlohmann::json& document, const nlohmann::json& changes) {
  world_protocol::CellRevision r;
  r.cell_revision = number;
  r.previous_revision = number - 1;
  r.cell_json = document.dump(2);
  r.sha256 = "revision-" + std::to_string(number);
  r.changes_json = changes.dump();
  r.who = "integration-test";
  rigger_world_CellRevision wire{};
  world_protocol::to_wire(r, wire);
  return writer.write(wire);
}

/// Whether the detail `service` announces in its service state (a cell follower's outcome) contains `text`
/// within `timeout`.
inline bool service_detail_says(Cell& cell, const std::string& service, const std::string& text,
                                std::chrono::milliseconds timeout = std::chrono::seconds(10)) {
  return cell.wait_until(
      [&] {
        cell.directory().update();
        const auto it = cell.directory().services().find(service);
        return it != cell.directory().services().end() && it->second.detail.find(text) != std::string::npos;
      },
      timeout);
}

}  // namespace rigger::testing
