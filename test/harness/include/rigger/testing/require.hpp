#pragma once
/// @file
/// A test that cannot run on this machine (no chromium, no root for network namespaces, …) is skipped on
/// a developer's machine, saying why, and FAILS in CI (CI=true), where every test must run: a CI machine
/// missing a tool must not silently drop the tests that need it.
///
///   RIGGER_REQUIRE_OR_SKIP(geteuid() == 0, "network namespaces need root (CAP_NET_ADMIN)");

#include <cstdlib>
#include <cstring>

#include <gtest/gtest.h>

namespace rigger::testing {

/// True when the CI variable is "true" (CI runs `.ci/run` so).
inline bool in_ci() {
  const char* ci = std::getenv("CI");
  return ci != nullptr && std::strcmp(ci, "true") == 0;
}

}  // namespace rigger::testing

/// Skips the test (returns from the calling function) with `why` unless `condition`; in CI fails instead.
#define RIGGER_REQUIRE_OR_SKIP(condition, why)                                 \
  do {                                                                         \
    if (!(condition)) {                                                        \
      if (::rigger::testing::in_ci()) {                                        \
        FAIL() << "cannot run on this machine, and CI=true: " << (why);        \
      } else {                                                                 \
        GTEST_SKIP() << (why);                                                 \
      }                                                                        \
    }                                                                          \
  } while (0)
