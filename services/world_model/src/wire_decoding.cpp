#include "wire_decoding.hpp"

#include <cmath>

#include "rigger/base/bounded_json.hpp"
#include "world_json.hpp"

namespace rigger::world {
namespace {

using nlohmann::json;

DecodeError error(std::string code, std::string message) {
  return DecodeError{std::move(code), std::move(message)};
}

// Ids are echoed in messages: clip what we quote so a megabyte of garbage makes a short reason.
std::string quote_id(const std::string& s) {
  constexpr std::size_t kMaxQuoted = 80;
  std::string out = s.size() > kMaxQuoted ? s.substr(0, kMaxQuoted) + "..." : s;
  for (char& c : out) {
    if (static_cast<unsigned char>(c) < 0x20 || static_cast<unsigned char>(c) >= 0x7f) c = '?';
  }
  return "\"" + out + "\"";
}

std::optional<DecodeError> check_id(const std::string& field, const std::string& value) {
  if (is_valid_identifier(value)) return std::nullopt;
  return error("BAD_ID", field + " " + quote_id(value) + ": expected 1 to 64 characters from [A-Za-z0-9_.-]");
}

}  // namespace

Decoded<EntityUpdate> decode_update(const rigger_world_EntityUpdate& wire) {
  return decode_update(world_protocol::from_wire(wire));
}

Decoded<EntityUpdate> decode_update(const world_protocol::Update& sent) {
  EntityUpdate u;
  u.entity_id = sent.entity_id;
  u.source = sent.source;
  if (auto e = check_id("entity_id", u.entity_id)) return *e;
  if (u.source.empty()) return error("MISSING_SOURCE", "source is empty");
  if (u.source.size() > 256) return error("BAD_ID", "source: expected at most 256 characters");

  if (!sent.stamp) return error("BAD_STAMP", "stamp.nanosec: expected < 1e9");
  u.stamp = *sent.stamp;

  const std::string& parent = sent.parent_frame;
  if (!parent.empty()) {
    if (auto e = check_id("parent_frame", parent)) return *e;
    u.parent = parent;
  }
  if (sent.pose) {
    const world_protocol::PoseAsSent& p = *sent.pose;
    if (!p.position_m.allFinite() || !p.orientation.coeffs().allFinite()) {
      return error("NOT_FINITE", "pose of " + quote_id(u.entity_id) + ": NaN or infinity");
    }
    // Kept as sent (not normalised): the store rejects a non-unit quaternion with its own code.
    u.pose = PoseValue{p.position_m, p.orientation};
  }
  if (sent.covariance) {
    const Covariance6d& cov = *sent.covariance;
    for (int i = 0; i < 36; ++i) {
      if (!std::isfinite(cov(i / 6, i % 6))) {
        return error("NOT_FINITE",
                     "covariance[" + std::to_string(i) + "] of " + quote_id(u.entity_id) + ": NaN or infinity");
      }
    }
    u.covariance = cov;
  }
  if (sent.quality) {
    if (!std::isfinite(*sent.quality))
      return error("NOT_FINITE", "quality of " + quote_id(u.entity_id) + ": NaN or infinity");
    u.quality = *sent.quality;
  }
  u.localized = sent.localized;

  const std::string& attributes = sent.attributes_json;
  if (!attributes.empty()) {
    if (attributes.size() > kMaxAttributesJsonBytes) {
      return error("BAD_ATTRIBUTES", "attributes_json: expected at most " + std::to_string(kMaxAttributesJsonBytes) +
                                         " bytes, got " + std::to_string(attributes.size()));
    }
    // Nesting bounded while parsing, not after, so deep input is refused before it is built; the store
    // then checks the exact depth of the values it keeps (world_store.cpp).
    JsonParseResult patch = parse_json_bounded(attributes, {kMaxAttributesJsonBytes, kMaxAttributeDepth + 1});
    if (!patch.ok()) {
      return error("BAD_ATTRIBUTES", "attributes_json: expected a JSON object nested at most " +
                                         std::to_string(kMaxAttributeDepth) + " levels: " + patch.error->to_string());
    }
    if (!patch.value.is_object()) return error("BAD_ATTRIBUTES", "attributes_json: expected a JSON object");
    u.attributes_patch = std::move(patch.value);
  }
  return u;
}

Decoded<EntityUpdate> decode_tracked_pose(const rigger_vision_TrackedPose& wire) {
  // The same checks as an update: build the equivalent update sample and decode that.
  rigger_world_EntityUpdate u{};
  std::string source = kTrackerSource, empty;
  u.source = source.data();
  u.entity_id = wire.object_id;
  u.parent_frame = wire.tracked && wire.header.frame_id ? wire.header.frame_id : empty.data();
  u.attributes_json = empty.data();
  u.stamp = wire.header.stamp;
  u.has_localized = true;
  u.localized = wire.tracked;
  if (wire.tracked) {
    u.has_pose = true;
    u.pose = wire.pose;
    u.has_quality = true;
    u.quality = wire.quality;
    bool all_zero = true;
    for (double c : wire.pose.covariance) all_zero = all_zero && c == 0.0;
    u.has_covariance = !all_zero && !(wire.pose.covariance[0] < 0.0);
  }
  return decode_update(u);
}

Decoded<WorldQuery> decode_query(const rigger_world_WorldQuery& wire) {
  return decode_query(world_protocol::from_wire(wire));
}

Decoded<WorldQuery> decode_query(const world_protocol::Query& sent) {
  WorldQuery q;
  q.client_id = sent.client_id;
  q.request_id = sent.request_id;
  q.entity_id = sent.entity_id;
  q.frame_id = sent.frame_id;
  q.feature_id = sent.feature_id;
  if (!sent.kind) return error("BAD_QUERY", "kind " + std::to_string(sent.wire_kind) + ": expected 0 to 4");
  q.kind = *sent.kind;
  if (q.kind != QueryKind::kList) {
    if (auto e = check_id("entity_id", q.entity_id)) return *e;
  }
  if (q.kind == QueryKind::kPose) {
    if (auto e = check_id("frame_id", q.frame_id)) return *e;
    if (!q.feature_id.empty()) {
      if (auto e = check_id("feature_id", q.feature_id)) return *e;
    }
  }
  if (sent.list_kind_unknown) {
    return error("BAD_QUERY", "list_kind " + std::to_string(sent.wire_list_kind) + ": expected 0 to 2");
  }
  if (sent.list_kind) {
    switch (*sent.list_kind) {
      case world_protocol::EntityKind::kObject:
        q.list_kind = EntityKind::kObject;
        break;
      case world_protocol::EntityKind::kDevice:
        q.list_kind = EntityKind::kDevice;
        break;
      case world_protocol::EntityKind::kFrame:
        q.list_kind = EntityKind::kFrame;
        break;
    }
  }
  if (!std::isfinite(sent.max_age_s)) return error("BAD_QUERY", "max_age_s: expected a finite number of seconds");
  if (q.kind == QueryKind::kIsLocalized && sent.max_age_s > 0.0) {
    // Beyond ~292 years nanoseconds overflow; such an age limit means "any age".
    if (sent.max_age_s < 9.0e9) {
      q.max_age = std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::duration<double>(sent.max_age_s));
    }
  }
  return q;
}

}  // namespace rigger::world
