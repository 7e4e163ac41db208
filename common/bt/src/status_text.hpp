#pragma once
/// @file
/// How the engine words the messages of node statuses (engine.cpp and tree_mechanics.cpp).
#include <cstdio>
#include <string>

#include "rigger/bt/tree_spec.hpp"

namespace rigger::bt {

/// `s` in seconds, shortest form ("%g").
inline std::string format_seconds(Seconds s) {
  char buffer[32];
  std::snprintf(buffer, sizeof buffer, "%g", s.count());
  return buffer;
}

/// `text`, then ": detail" when there is a detail.
inline std::string with_detail(std::string text, const std::string& detail) {
  if (!detail.empty()) {
    text += ": " + detail;
  }
  return text;
}

}  // namespace rigger::bt
