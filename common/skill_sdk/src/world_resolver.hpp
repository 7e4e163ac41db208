#pragma once
/// @file
/// FeatureResolver over the world model (rigger::world_client::WorldClient::feature_pose): a
/// feature_ref "entity/feature" resolves to T_frame_feature. A ref with more than two parts
/// ("target/screw_holes/h3") uses its first part as the entity and its last as the feature id (feature
/// ids are unique within an entity). Thread safety: the event loop thread.

#include <map>

#include "rigger/skill_sdk/primitives.hpp"
#include "rigger/world_client/world_client.hpp"

namespace rigger::skill_sdk {

class WorldFeatureResolver final : public FeatureResolver {
 public:
  explicit WorldFeatureResolver(world_client::WorldClient& client) : client_(client) {}
  OpId resolve(const std::string& ref, const std::string& frame, std::chrono::nanoseconds timeout,
               std::function<void(const OpResult&, const ResolvedFeature&)> done) override;
  void cancel(OpId id) override { client_.cancel(id); }

 private:
  world_client::WorldClient& client_;
};

}  // namespace rigger::skill_sdk
