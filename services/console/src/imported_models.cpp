#include "imported_models.hpp"

#include <utility>

namespace rigger::console {

void ImportedModels::keep(const std::string& sha256, const std::string& name, std::string bytes) {
  std::lock_guard<std::mutex> lock(mutex_);
  for (auto it = models_.begin(); it != models_.end(); ++it) {
    if (it->sha256 != sha256) continue;
    bytes_ -= it->step.size();
    models_.erase(it);
    break;
  }
  bytes_ += bytes.size();
  models_.push_back({sha256, name, std::move(bytes)});
  while (models_.size() > 1 && (models_.size() > kMaxImports || bytes_ > kMaxImportedBytes)) {
    bytes_ -= models_.front().step.size();
    models_.pop_front();
  }
}

void ImportedModels::touch(const std::string& sha256) {
  std::lock_guard<std::mutex> lock(mutex_);
  for (auto it = models_.begin(); it != models_.end(); ++it) {
    if (it->sha256 != sha256) continue;
    world_protocol::CellModel model = std::move(*it);
    models_.erase(it);
    models_.push_back(std::move(model));
    return;
  }
}

std::optional<world_protocol::CellModel> ImportedModels::find(const std::string& sha256) const {
  std::lock_guard<std::mutex> lock(mutex_);
  for (const world_protocol::CellModel& m : models_)
    if (m.sha256 == sha256) return m;
  return std::nullopt;
}

}  // namespace rigger::console
