#include "rigger/crane_protocol/crane_config.hpp"

#include <array>
#include <nlohmann/json.hpp>

#include "rigger/cell_config/cell_file.hpp"

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
  // The one cell-file reader checks the whole file (bounded parse, format, pointers) first.
  const cell::CellFile cell = cell::rethrow_as<CraneConfigError>([&] { return cell::load_cell_file(path); });
  const cell::CellEntity* crane = cell.find(crane_id);
  if (crane == nullptr) {
    throw CraneConfigError(path + ": /entities: no entity with id \"" + std::string(crane_id) + "\"");
  }
  try {
    return crane_limits_from_attributes(crane->attributes, crane->pointer + "/attributes");
  } catch (const CraneConfigError& e) {
    throw CraneConfigError(path + ": " + e.what());
  }
}

}  // namespace rigger::crane
