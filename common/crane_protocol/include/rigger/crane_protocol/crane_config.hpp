#pragma once
// The crane's limits from the cell description (deploy/cell/*.json).

#include <nlohmann/json_fwd.hpp>
#include <stdexcept>
#include <string>
#include <string_view>

#include "rigger/crane_protocol/register_map.hpp"

namespace rigger::crane {

/// A cell description that does not describe a usable crane. The message names the file (when
/// known), the JSON pointer and what was expected.
class CraneConfigError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// Limits from a crane entity's "attributes" object:
///   bridge_range_m, trolley_range_m, rope_length_range_m: [min, max];
///   rail_height_m; max_speed_mps, max_accel_mps2: [x, y, z]; rated_load_kg.
/// The hoist axis is the hook height, z up: [rail_height - rope_max, rail_height - rope_min].
/// `pointer` is the JSON pointer of `attributes`, used in error messages.
/// Throws CraneConfigError.
CraneLimits crane_limits_from_attributes(const nlohmann::json& attributes,
                                         const std::string& pointer);

/// Limits of the entity `crane_id` in the cell description file at `path`.
/// Throws CraneConfigError (unreadable file, malformed JSON, missing entity or fields).
CraneLimits load_crane_limits(const std::string& path, std::string_view crane_id = "crane");

}  // namespace rigger::crane
