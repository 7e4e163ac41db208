#include "rigger/crane_protocol/crane_config.hpp"

#include <array>
#include <fstream>
#include <nlohmann/json.hpp>

namespace rigger::crane {
namespace {

const nlohmann::json& member(const nlohmann::json& object, const std::string& pointer,
                             const char* key) {
  if (!object.is_object() || !object.contains(key)) {
    throw CraneConfigError(pointer + "/" + key + ": missing");
  }
  return object.at(key);
}

double number(const nlohmann::json& value, const std::string& pointer) {
  if (!value.is_number()) {
    throw CraneConfigError(pointer + ": expected a number");
  }
  return value.get<double>();
}

template <std::size_t N>
std::array<double, N> numbers(const nlohmann::json& object, const std::string& pointer,
                              const char* key) {
  const auto& value = member(object, pointer, key);
  const std::string where = pointer + "/" + key;
  if (!value.is_array() || value.size() != N) {
    throw CraneConfigError(where + ": expected an array of " + std::to_string(N) + " numbers");
  }
  std::array<double, N> out{};
  for (std::size_t i = 0; i < N; ++i) {
    out[i] = number(value[i], where + "/" + std::to_string(i));
  }
  return out;
}

}  // namespace

CraneLimits crane_limits_from_attributes(const nlohmann::json& attributes,
                                         const std::string& pointer) {
  const auto bridge = numbers<2>(attributes, pointer, "bridge_range_m");
  const auto trolley = numbers<2>(attributes, pointer, "trolley_range_m");
  const auto rope = numbers<2>(attributes, pointer, "rope_length_range_m");
  const double rail_height =
      number(member(attributes, pointer, "rail_height_m"), pointer + "/rail_height_m");
  const auto speed = numbers<3>(attributes, pointer, "max_speed_mps");
  const auto accel = numbers<3>(attributes, pointer, "max_accel_mps2");
  const double rated =
      number(member(attributes, pointer, "rated_load_kg"), pointer + "/rated_load_kg");

  CraneLimits limits;
  limits.position_min_m = {bridge[0], trolley[0], rail_height - rope[1]};
  limits.position_max_m = {bridge[1], trolley[1], rail_height - rope[0]};
  limits.max_speed_mps = {speed[0], speed[1], speed[2]};
  limits.max_accel_mps2 = {accel[0], accel[1], accel[2]};
  limits.rated_load_kg = rated;
  if (const auto problem = check_limits(limits)) {
    throw CraneConfigError(pointer + ": " + *problem);
  }
  return limits;
}

CraneLimits load_crane_limits(const std::string& path, std::string_view crane_id) {
  std::ifstream in(path);
  if (!in) {
    throw CraneConfigError(path + ": cannot open");
  }
  nlohmann::json cell;
  try {
    cell = nlohmann::json::parse(in);
  } catch (const nlohmann::json::parse_error& e) {
    throw CraneConfigError(path + ": malformed JSON: " + e.what());
  }
  if (!cell.is_object() || !cell.contains("entities") || !cell["entities"].is_array()) {
    throw CraneConfigError(path + ": /entities: expected an array");
  }
  const auto& entities = cell["entities"];
  for (std::size_t i = 0; i < entities.size(); ++i) {
    const auto& entity = entities[i];
    const bool match = entity.is_object() && entity.contains("id") && entity["id"].is_string() &&
                       entity["id"].get<std::string>() == crane_id;
    if (match) {
      const std::string pointer = "/entities/" + std::to_string(i);
      try {
        return crane_limits_from_attributes(member(entity, pointer, "attributes"),
                                            pointer + "/attributes");
      } catch (const CraneConfigError& e) {
        throw CraneConfigError(path + ": " + e.what());
      }
    }
  }
  throw CraneConfigError(path + ": /entities: no entity with id \"" + std::string(crane_id) + "\"");
}

}  // namespace rigger::crane
