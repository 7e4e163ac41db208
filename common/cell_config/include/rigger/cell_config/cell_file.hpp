#pragma once
/// @file
/// The one reader of the cell file (`deploy/cell/*.json`, format in docs/world-model.md): the frame tree,
/// device poses, camera intrinsics, object models and CAD features as typed entities. Every rule of the
/// format is checked at load time; the first violation throws a CellFileError naming the file, the JSON
/// pointer and what was expected. Unknown keys are rejected (a typo must not silently drop a setting); a
/// "comment" key is allowed in every object. Entity attributes are free JSON; a consumer that needs some
/// of them checks them with AttributeReader, which reports errors the same way.
///
/// Used by the world model, the simulated cell's physics and camera and the vision tracker. Everything
/// here is a value or a pure function: thread-safe for concurrent readers.

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include <Eigen/Geometry>
#include <nlohmann/json.hpp>

#include "rigger/cell_config/cell_types.hpp"

namespace rigger::cell {

/// A cell file violation. `what()` reads "<file>: <pointer>: expected <expected>[, got <got>]"
/// ("(document)" stands for the empty pointer).
class CellFileError : public std::runtime_error {
 public:
  CellFileError(std::string file, std::string pointer, std::string expected, std::string got = {});

  /// The file name (or the source name given to the parser).
  const std::string& file() const { return file_; }
  /// RFC 6901 JSON pointer of the offending value ("" for the whole document).
  const std::string& pointer() const { return pointer_; }
  /// What was expected there, in words.
  const std::string& expected() const { return expected_; }

 private:
  std::string file_;
  std::string pointer_;
  std::string expected_;
};

/// One validated entity of the cell file.
struct CellEntity {
  std::string id;
  EntityKind kind = EntityKind::kObject;
  std::string parent;  ///< id of the parent entity; empty only for a root frame
  /// The entity's pose in its parent's frame; std::nullopt when the file gives none (a tool whose pose
  /// is reported at run time, or a root frame).
  std::optional<Eigen::Isometry3d> pose_parent_entity;
  /// The pose is a usable estimate from the start: by default true for devices and frames with a pose,
  /// false for objects (perception localizes them); the file's "localized" overrides it.
  bool localized = false;
  nlohmann::json attributes = nlohmann::json::object();  ///< free; "description" is folded in here
  std::optional<ObjectModel> model;                      ///< objects only
  std::optional<CameraIntrinsics> camera;                ///< devices only
  CadFeatures features;                                  ///< not on frames
  std::optional<CalibrationBoard> calibration_board;     ///< devices only: a board on the tool
  std::string pointer;                                   ///< where it is in the file, e.g. "/entities/3"
};

/// A validated cell file: entities in file order, parents known, ids unique, no cycles, marker ids
/// unique per dictionary across the cell, insertion targets known.
struct CellFile {
  std::string source;    ///< the file (or source name) it was read from
  int cell_version = 0;  ///< always kCellVersion
  std::string description;
  std::vector<CellEntity> entities;

  /// The entity with this id, or nullptr.
  const CellEntity* find(std::string_view id) const;
  /// The entity with this id. @throws CellFileError at "/entities" saying it needs one (for `purpose`).
  const CellEntity& require(std::string_view id, std::string_view purpose) const;
  /// The entity's pose in the root frame of its tree: its pose composed with its parents' (an entity
  /// without a pose sits at its parent's origin). @throws CellFileError for an unknown id.
  Eigen::Isometry3d pose_root_entity(std::string_view id) const;
  /// @throws CellFileError naming the first CAD rule (features.*.cad) whose pose has not been derived
  ///   from its STEP model yet (cell::derive_cad_features), for `reader` that needs the poses.
  void require_cad_derived(std::string_view reader) const;
  /// Throws CellFileError(source, pointer, expected, got).
  [[noreturn]] void fail(const std::string& pointer, const std::string& expected, const std::string& got = {}) const;
};

/// Checked access to one entity's free attributes; errors name the file and
/// "<entity pointer>/attributes/<key>". Holds references: keep the CellFile alive.
class AttributeReader {
 public:
  AttributeReader(const CellFile& file, const CellEntity& entity);

  /// A finite number. @throws CellFileError when missing or not a finite number.
  double number(std::string_view key) const;
  /// A finite number > 0.
  double positive(std::string_view key) const;
  /// [min, max] of finite numbers with min < max.
  Eigen::Vector2d range(std::string_view key) const;
  /// Three finite numbers > 0 (e.g. per-axis limits).
  Eigen::Vector3d positive3(std::string_view key) const;
  /// A string.
  std::string text(std::string_view key) const;
  /// The pointer of the attribute `key`, for further checks by the caller.
  std::string pointer(std::string_view key) const;

 private:
  const nlohmann::json& value(std::string_view key, const std::string& expected) const;

  const CellFile& file_;
  const CellEntity& entity_;
};

/// Where the centre of an object's box (the box shorthand, axes along its edges) sits in the object's frame,
/// from the model's words for its frame: "box centre" (or none), "centre of the top face", "centre of the
/// bottom face". The one reading of those words: the physics and the camera place the box alike.
/// @throws CellFileError at ".../model/frame" for other words, at ".../model/shape" without a box.
Eigen::Vector3d box_centre_in_object_frame(const CellFile& file, const CellEntity& entity);

/// The only format version this reader reads.
inline constexpr int kCellVersion = 1;
/// Inputs larger than this are refused before parsing (bytes).
inline constexpr std::size_t kMaxCellFileBytes = 4 * 1024 * 1024;
/// JSON nesting deeper than this is refused while parsing.
inline constexpr int kMaxCellFileDepth = 32;

/// The folder the relative model paths (model.step) of the cell file at `cell_file` resolve against: its
/// folder ("." when the path has none). A cell document received over DDS (a cell revision) resolves
/// against the receiving reader's own configured cell file: models travel with the cell folder, only the
/// document travels on the wire.
std::filesystem::path cell_model_folder(const std::filesystem::path& cell_file);

/// Reads and validates the cell file at `path`.
/// @throws CellFileError on an unreadable file or any violation.
CellFile load_cell_file(const std::filesystem::path& path);

/// Parses and validates cell file text; `source` names it in errors.
/// @throws CellFileError on malformed JSON (including duplicate keys), oversized or too deeply nested
///   input, or any violation.
CellFile parse_cell_file(std::string_view text, const std::string& source);

/// Validates an already parsed document (e.g. built in code); `source` names it in errors.
/// @throws CellFileError on any violation (including NaN or infinite numbers).
CellFile cell_file_from_json(const nlohmann::json& document, const std::string& source);

/// Returns read(), rethrowing a CellFileError as Error(what()): for readers whose callers catch their own
/// error type (e.g. sim::CellGeometryError).
template <typename Error, typename Read>
auto rethrow_as(Read&& read) -> decltype(read()) {
  try {
    return read();
  } catch (const CellFileError& error) {
    throw Error(error.what());
  }
}

}  // namespace rigger::cell
