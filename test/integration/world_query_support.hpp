#pragma once
/// @file
/// What the world model says of an entity, asked by a test through a client of its own (the one every
/// service uses, rigger/world_client), on the test's event loop. Made when the cell starts, as services
/// make theirs, so that discovery is long done when it asks (the client also asks again when a reply was
/// lost to a discovery still under way).

#include <chrono>
#include <optional>
#include <string>

#include "rigger/testing/cell.hpp"
#include "rigger/world_client/world_client.hpp"

namespace rigger::testing {

class WorldQuery {
 public:
  explicit WorldQuery(Cell& cell) : cell_(cell), client_(cell.participant(), cell.loop(), null_logger(), "test-world-query") {}

  /// Whether the world model holds `entity` as localized (any age); nullopt when it did not answer in 5 s
  /// or does not know the entity.
  std::optional<bool> localized(const std::string& entity) {
    std::optional<world_client::Reply> reply;
    client_.is_localized(entity, 0.0, std::chrono::seconds(5), [&](const world_client::Reply& r) { reply = r; });
    if (!cell_.wait_until([&] { return reply.has_value(); }, std::chrono::seconds(6)) || !reply->ok) return std::nullopt;
    return reply->localized;
  }

  /// The pose of `entity` in `frame` the world model answers (QUERY_POSE); nullopt when it did not answer in
  /// 5 s, refused or has no pose.
  std::optional<Eigen::Isometry3d> pose(const std::string& entity, const std::string& frame = "world") {
    std::optional<world_client::Reply> reply;
    client_.pose(entity, frame, std::chrono::seconds(5), [&](const world_client::Reply& r) { reply = r; });
    if (!cell_.wait_until([&] { return reply.has_value(); }, std::chrono::seconds(6)) || !reply->ok) return std::nullopt;
    return reply->pose;
  }

  /// The CAD features the world model serves for `entity` (QUERY_FEATURES: the cell file's features format,
  /// the rules' poses derived); nullopt when it did not answer in 5 s or refused.
  std::optional<nlohmann::json> features(const std::string& entity) {
    std::optional<world_client::Reply> reply;
    client_.features(entity, std::chrono::seconds(5), [&](const world_client::Reply& r) { reply = r; });
    if (!cell_.wait_until([&] { return reply.has_value(); }, std::chrono::seconds(6)) || !reply->ok) return std::nullopt;
    return reply->result;
  }

 private:
  Cell& cell_;
  world_client::WorldClient client_;
};

}  // namespace rigger::testing
