#pragma once
/// @file
/// A number with a fixed count of decimals, for the skills' messages ("0.42", "1.5").

#include <cstdio>
#include <string>

namespace rigger::skill_executor {

inline std::string fixed(double value, int digits) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.*f", digits, value);
  return buf;
}

}  // namespace rigger::skill_executor
