#pragma once
// A test helper of rigger_base_test: the message of the ConfigError a call throws.

#include <string>

#include "rigger/base/config.hpp"

namespace rigger {

/// The message of the ConfigError thrown by f, or "" when nothing was thrown.
template <typename F>
std::string error_of(F&& f) {
  try {
    f();
  } catch (const ConfigError& e) {
    return e.what();
  }
  return "";
}

}  // namespace rigger
