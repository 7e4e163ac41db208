#include "rigger/skill/units.hpp"

#include <array>

namespace rigger::skill {
namespace {

struct Conversion {
  std::string_view from;
  std::string_view si;
  double factor;
};

constexpr double kPi = 3.14159265358979323846;

// Deliberately short: units people actually type for crane and robot parameters. Anything
// else must be written in the declared SI unit.
constexpr std::array<Conversion, 14> kConversions{{
    {"mm", "m", 1e-3},
    {"cm", "m", 1e-2},
    {"km", "m", 1e3},
    {"ms", "s", 1e-3},
    {"min", "s", 60.0},
    {"h", "s", 3600.0},
    {"kN", "N", 1e3},
    {"kN/s", "N/s", 1e3},
    {"mm/s", "m/s", 1e-3},
    {"deg", "rad", kPi / 180.0},
    {"deg/s", "rad/s", kPi / 180.0},
    {"g", "kg", 1e-3},
    {"t", "kg", 1e3},
    {"Nmm", "Nm", 1e-3},
}};

}  // namespace

const std::vector<std::string_view>& si_units() {
  static const std::vector<std::string_view> kUnits{
      "", "m", "s", "N", "N/s", "Nm", "m/s", "m/s^2", "rad", "rad/s", "rad/s^2", "kg", "Hz", "N/m", "Ns/m"};
  return kUnits;
}

bool is_si_unit(std::string_view unit) {
  for (const auto u : si_units()) {
    if (u == unit) {
      return true;
    }
  }
  return false;
}

std::optional<double> conversion_factor(std::string_view from, std::string_view si) {
  if (from == si && is_si_unit(si)) {
    return 1.0;
  }
  for (const auto& c : kConversions) {
    if (c.from == from && c.si == si) {
      return c.factor;
    }
  }
  return std::nullopt;
}

}  // namespace rigger::skill
