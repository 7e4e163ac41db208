#pragma once
/// @file
/// The STEP files imported in the Planner that may still become cell objects: their bytes, kept in the
/// console until the revision that adds them goes to the world model with them (a cell revision request
/// carries the models the document pins, idl/world.idl CellRequest.models). Bounded: the newest
/// kMaxImports files, at most kMaxImportedBytes together; older ones are forgotten (the page then asks
/// for the file again). Thread-safe: the HTTP threads share it.
#include <cstddef>
#include <deque>
#include <mutex>
#include <optional>
#include <string>

#include "rigger/world_protocol/cell_protocol.hpp"

namespace rigger::console {

class ImportedModels {
 public:
  static constexpr std::size_t kMaxImports = 4;
  static constexpr std::size_t kMaxImportedBytes = 256U * 1024U * 1024U;

  /// Keeps `bytes` (read by the CAD service as sha256 `sha256`) under the file's `name`.
  void keep(const std::string& sha256, const std::string& name, std::string bytes);
  /// Makes `sha256`'s file the newest kept (the last one forgotten), when it is kept.
  void touch(const std::string& sha256);
  /// The imported file of `sha256` (its name is the uploaded file's), or none when not (or no longer) kept.
  std::optional<world_protocol::CellModel> find(const std::string& sha256) const;

 private:
  mutable std::mutex mutex_;
  std::deque<world_protocol::CellModel> models_;  ///< oldest first
  std::size_t bytes_ = 0;
};

}  // namespace rigger::console
