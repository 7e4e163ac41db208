#pragma once
/// @file
/// What the world model says of an entity, asked by a test through a client of its own (the one every
/// service uses, rigger/world_client), on the test's event loop.

#include <chrono>
#include <optional>
#include <string>

#include "rigger/testing/cell.hpp"
#include "rigger/world_client/world_client.hpp"

namespace rigger::testing {

/// Whether the world model holds `entity` as localized (any age); nullopt when it did not answer in 5 s or
/// does not know the entity.
inline std::optional<bool> world_localized(Cell& cell, const std::string& entity) {
  world_client::WorldClient client(cell.participant(), cell.loop(), null_logger(), "test-world-query");
  std::optional<world_client::Reply> reply;
  client.is_localized(entity, 0.0, std::chrono::seconds(5), [&](const world_client::Reply& r) { reply = r; });
  if (!cell.wait_until([&] { return reply.has_value(); }, std::chrono::seconds(6)) || !reply->ok) return std::nullopt;
  return reply->localized;
}

}  // namespace rigger::testing
