#pragma once
/// @file
/// The CAD service's logic, without DDS: a catalog of loaded models (the cell's objects' STEP models,
/// models loaded by path or content) that answers queries (load, features, tessellation, frames, derived
/// skill parameters). Every answer carries ok, a code and a message; nothing a client sends throws out of
/// answer(). Loop thread only.

#include "rigger/cad/features.hpp"
#include "rigger/cad/tessellation.hpp"
#include "rigger/cell_config/cell_file.hpp"

#include <cstdint>
#include <filesystem>
#include <map>
#include <optional>
#include <string>
#include <vector>

namespace rigger::cad_service {

enum class QueryKind { kLoad, kFeatures, kTessellation, kFrame, kDerive };

/// A decoded CadRequest.
struct CadQuery {
  QueryKind kind = QueryKind::kLoad;
  std::string model;    ///< "object:<id>", "sha256:<hex>" or a file path
  std::string content;  ///< STEP bytes (LOAD by content) or empty
  std::string args_json;
};

/// What goes into a CadReply.
struct CadAnswer {
  bool ok = false;
  std::string code;  ///< "OK" or CAD_*
  std::string message;
  std::string model_sha256;
  std::string result_json;
  std::vector<std::uint8_t> data;
};

struct CadServiceSettings {
  /// The cell file; its objects' "model.step" files are loaded at start (relative to its folder).
  std::filesystem::path cell_file;
  /// Folders a request may name a file in (besides the cell's models); empty: only the cell's models.
  std::vector<std::filesystem::path> allowed_dirs;
  cad::ReadLimits limits;
  /// Models kept besides the cell's objects' (the oldest is dropped first).
  std::size_t max_models = 16;
};

class CadService {
 public:
  /// Loads the cell file (throws its CellFileError) and each object's STEP model; a model that cannot be
  /// read is remembered with its error, which requests for that object get.
  explicit CadService(CadServiceSettings settings);

  CadAnswer answer(const CadQuery& query);

  /// The cell's objects become `cell`'s (a new cell revision; relative model paths resolve against
  /// `folder`): a model already loaded from the same path is kept, the others are read as at start (a model
  /// that cannot be read is remembered with its error); a model no object names any more is dropped like a
  /// requested one (oldest first, beyond max_models).
  void follow(const cell::CellFile& cell, const std::filesystem::path& folder);

  /// The configured cell file.
  const std::filesystem::path& cell_file() const { return settings_.cell_file; }

  /// object id -> "ok <sha256>" or the error its model gave at start (for the start-up log).
  const std::map<std::string, std::string>& object_status() const { return object_status_; }

 private:
  struct Entry {
    cad::Model model;
    cad::Features features;
    std::optional<cad::Tessellation> mesh;
  };

  Entry& find_model(const std::string& spec);
  std::filesystem::path readable(const std::string& spec) const;
  CadAnswer load_node(const CadQuery& query);
  Entry& add(cad::Model model, bool pinned);
  CadAnswer frame(Entry& entry, const std::string& args_json) const;
  CadAnswer derive(Entry& entry, const std::string& args_json) const;

  CadServiceSettings settings_;
  std::map<std::string, Entry> models_;            // by sha256
  std::vector<std::string> unpinned_;              // load order of models not named by the cell
  std::map<std::string, std::string> objects_;     // object id -> sha256
  std::map<std::string, std::string> object_errors_;  // object id -> "CODE\tmessage"
  std::map<std::string, std::string> object_status_;
  std::map<std::string, std::filesystem::path> object_paths_;  // object id -> its STEP file
};

}  // namespace rigger::cad_service
