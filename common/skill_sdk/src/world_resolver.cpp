#include "world_resolver.hpp"

namespace rigger::skill_sdk {

std::optional<std::pair<std::string, std::string>> split_feature_ref(const std::string& ref) {
  const auto first = ref.find('/');
  const auto last = ref.rfind('/');
  if (first == std::string::npos || first == 0 || last + 1 >= ref.size()) return std::nullopt;
  return std::make_pair(ref.substr(0, first), ref.substr(last + 1));
}

OpId WorldFeatureResolver::resolve(const std::string& ref, const std::string& frame, std::chrono::nanoseconds timeout,
                                   std::function<void(const OpResult&, const ResolvedFeature&)> done) {
  const auto parts = split_feature_ref(ref);
  if (!parts) {
    // Checked params never get here (feature_ref syntax is validated); answer like the world model would.
    done(OpResult::failure("UNKNOWN_FEATURE", "'" + ref + "' is not entity/feature"), ResolvedFeature{});
    return 0;
  }
  return client_.feature_pose(
      parts->first, parts->second, frame, std::chrono::duration_cast<std::chrono::milliseconds>(timeout),
      [ref, done = std::move(done)](const world_client::Reply& reply) {
        ResolvedFeature feature;
        feature.ref = ref;
        if (!reply.ok) {
          done(OpResult::failure(reply.code.empty() ? "WORLD_UNREACHABLE" : reply.code, reply.message), feature);
          return;
        }
        feature.frame = reply.frame;
        feature.pose = reply.pose;
        feature.localized = reply.localized;
        feature.age_s = reply.age_s;
        done(OpResult::success(), feature);
      });
}

}  // namespace rigger::skill_sdk
