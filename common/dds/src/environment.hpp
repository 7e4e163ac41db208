#pragma once
/// @file
/// rigger_dds's own reading of integer settings from the environment (RIGGER_DOMAIN,
/// RIGGER_LIVELINESS_LEASE_MS). Not installed: a detail of the library.

#include <cstdlib>
#include <optional>
#include <stdexcept>
#include <string>

namespace rigger::dds::detail {

/// The integer in $`name`, or nullopt when it is unset or empty.
/// @throws std::invalid_argument "NAME='value' is not `what` in [lo, hi]" when it is not such an integer.
inline std::optional<long> integer_from_environment(const char* name, long lo, long hi, const char* what) {
  const char* env = std::getenv(name);
  if (!env || !*env) return std::nullopt;
  char* end = nullptr;
  const long v = std::strtol(env, &end, 10);
  if (*end != '\0' || v < lo || v > hi) {
    throw std::invalid_argument(std::string(name) + "='" + env + "' is not " + what + " in [" + std::to_string(lo) +
                                ", " + std::to_string(hi) + "]");
  }
  return v;
}

}  // namespace rigger::dds::detail
