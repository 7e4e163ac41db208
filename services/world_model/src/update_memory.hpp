#pragma once
/// @file
/// The results of the last updates, by sender and sequence number. A sender that hears no result sends
/// its update again (a result written before the world model's writer has discovered a new sender is
/// lost: the topic is volatile); the repeat is answered with the result the update had, and not applied
/// a second time.

#include <cstddef>
#include <cstdint>
#include <deque>
#include <map>
#include <string>
#include <utility>

#include "rigger/world_protocol/world_protocol.hpp"

namespace rigger::world {

class UpdateMemory {
 public:
  /// Keeps the last `capacity` results (>= 1); the oldest is forgotten first.
  explicit UpdateMemory(std::size_t capacity = 4096);

  /// The result of the update `seq` from `source`, or nullptr when it is not (or no longer) known.
  const world_protocol::UpdateResult* find(const std::string& source, std::uint64_t seq) const;
  /// Remembers a result by its source and seq (a result already known is replaced).
  void remember(const world_protocol::UpdateResult& result);
  std::size_t size() const { return results_.size(); }

 private:
  using Key = std::pair<std::string, std::uint64_t>;
  std::size_t capacity_;
  std::map<Key, world_protocol::UpdateResult> results_;
  std::deque<Key> order_;  // oldest first
};

}  // namespace rigger::world
