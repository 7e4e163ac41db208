#pragma once
/// @file
/// For verbs that must reach every peer discovery will find (a reset of the safe stops, a listing of the
/// executors): peers on other hosts, or a riggerctl that has just started, may be a discovery round
/// behind the first match.

#include <algorithm>
#include <chrono>
#include <cstdint>
#include <functional>

#include "rigger/dds/pubsub.hpp"

namespace rigger::ctl {

/// After a first match: blocks until `count()` (matched readers or writers of `entity`) has not changed
/// for `quiet`, or `timeout` passed. Waitset on `entity`'s `status`, no polling.
inline void wait_for_quiet_matching(dds_entity_t entity, uint32_t status, const std::function<uint32_t()>& count,
                                    std::chrono::nanoseconds quiet, std::chrono::nanoseconds timeout) {
  const auto deadline = std::chrono::steady_clock::now() + timeout;
  for (auto seen = count();;) {
    const auto now = std::chrono::steady_clock::now();
    if (now >= deadline) return;
    const auto window = std::min<std::chrono::nanoseconds>(quiet, deadline - now);
    if (!dds::wait_for_status(entity, status, [&] { return count() != seen; }, window)) return;  // quiet
    seen = count();
  }
}

}  // namespace rigger::ctl
