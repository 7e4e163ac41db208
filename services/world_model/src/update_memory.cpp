#include "update_memory.hpp"

#include <algorithm>

namespace rigger::world {

UpdateMemory::UpdateMemory(std::size_t capacity) : capacity_(std::max<std::size_t>(capacity, 1)) {}

const world_protocol::UpdateResult* UpdateMemory::find(const std::string& source, std::uint64_t seq) const {
  const auto it = results_.find(Key(source, seq));
  return it == results_.end() ? nullptr : &it->second;
}

void UpdateMemory::remember(const world_protocol::UpdateResult& result) {
  Key key(result.source, result.seq);
  const auto [it, added] = results_.insert_or_assign(key, result);
  if (!added) return;
  order_.push_back(std::move(key));
  if (order_.size() > capacity_) {
    results_.erase(order_.front());
    order_.pop_front();
  }
}

}  // namespace rigger::world
