#pragma once
/// @file
/// A CAD model read from STEP with OpenCascade: its B-rep in metres, its product tree and the sha256 of
/// the bytes it came from. Reading is bounded (size, time, memory) and, by default, done in a child
/// process so that a crash of OCCT on a hostile file never takes down the caller.

#include <TopoDS_Shape.hxx>

#include <chrono>
#include <cstdint>
#include <filesystem>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include "rigger/base/sha256.hpp"

namespace rigger::cad {

/// Why a CAD operation failed; to_string() gives the code the service puts in CadReply::code.
enum class ErrorCode {
  kFileNotFound,      ///< the path does not exist or cannot be opened
  kTooLarge,          ///< the input is larger than ReadLimits::max_bytes
  kEmpty,             ///< zero bytes
  kNotStep,           ///< the bytes are not a STEP (ISO 10303-21) file, or OCCT cannot parse them
  kNoGeometry,        ///< a STEP file without a single face
  kTooDeep,           ///< the assembly is nested deeper than ReadLimits::max_assembly_depth
  kTimeout,           ///< reading took longer than ReadLimits::timeout (the reader was killed)
  kCrashed,           ///< the reader died (signal or memory limit) on this input
  kWriteFailed,       ///< a STEP or GLB file could not be written
  kBadReference,      ///< a face/edge/vertex/hole index or reference that does not exist
  kStaleReference,    ///< a reference whose signature no longer matches the model
  kNotAFrame,         ///< picks that cannot make a frame (not perpendicular, point off the face...)
  kNoUnits,           ///< a STEP file that declares no length unit (its numbers could be mm, inches or m)
};

/// "CAD_FILE_NOT_FOUND", "CAD_TOO_LARGE", ...
std::string_view to_string(ErrorCode code);

/// Every error of rigger::cad: a code and a message that says what and where.
class CadError : public std::runtime_error {
 public:
  CadError(ErrorCode code, const std::string& message) : std::runtime_error(message), code_(code) {}
  ErrorCode code() const noexcept { return code_; }

 private:
  ErrorCode code_;
};

/// A reference that no longer lands on the model (kStaleReference): `why()` says what differs, without
/// the "stale reference: " that what() begins with.
class StaleReference : public CadError {
 public:
  explicit StaleReference(const std::string& why) : CadError(ErrorCode::kStaleReference, "stale reference: " + why), why_(why) {}
  const std::string& why() const noexcept { return why_; }

 private:
  std::string why_;
};

/// Bounds on reading untrusted STEP input.
struct ReadLimits {
  std::uintmax_t max_bytes = 64ull << 20;                ///< larger inputs are refused before parsing
  std::chrono::milliseconds timeout{60'000};             ///< wall time of the reader (child killed after)
  std::uintmax_t max_memory_bytes = 4ull << 30;          ///< address-space limit of the reader child
  int max_assembly_depth = 32;                           ///< deeper product trees are refused
  bool isolate = true;  ///< read in a forked child process (false: in this process, e.g. for fuzzing)
};

/// One node of the product tree (STEP PRODUCT names, via OCCT's XCAF reader). A part used twice is two
/// nodes, each with its instance's name.
struct ProductNode {
  std::string name;      ///< the product's name (the instance's when the product has none)
  std::string instance;  ///< the instance's own name (the assembly usage's), "" for the root
  bool assembly = false;
  std::vector<ProductNode> children;
};

/// A read model. Lengths of the shape are metres whatever the file's unit. Copies share the shape.
/// Not thread-safe for concurrent tessellation (meshing stores triangles in the shared B-rep).
class Model {
 public:
  Model(TopoDS_Shape shape_m, ProductNode product, std::string sha256, std::string source);

  /// The B-rep in metres.
  const TopoDS_Shape& shape() const { return shape_; }
  /// The product tree; its root is the file (or the one top-level product).
  const ProductNode& product() const { return product_; }
  /// Hex sha256 of the STEP bytes (or of the B-rep when the model was built in memory).
  const std::string& sha256() const { return sha256_; }
  /// Where it came from: a path, "content", or a name given by the caller.
  const std::string& source() const { return source_; }

 private:
  TopoDS_Shape shape_;
  ProductNode product_;
  std::string sha256_;
  std::string source_;
};

/// Reads a STEP file. Throws CadError (kFileNotFound, kTooLarge, kEmpty, kNotStep, kNoGeometry, kNoUnits,
/// kTooDeep, kTimeout, kCrashed) with the path in the message.
Model read_step_file(const std::filesystem::path& path, const ReadLimits& limits = {});

/// Reads STEP bytes (e.g. sent over DDS); `source` names them in errors.
Model read_step_bytes(std::string_view bytes, const std::string& source, const ReadLimits& limits = {});

/// A model from a shape built in memory (lengths in metres); its sha256 is that of its binary B-rep.
Model model_from_shape(const TopoDS_Shape& shape_m, const std::string& name);

/// Writes `shape_m` (metres) as a STEP AP214 file in millimetres with one product named `product`.
/// Throws CadError(kWriteFailed).
void write_step(const TopoDS_Shape& shape_m, const std::string& product, const std::filesystem::path& path);

/// Why `model` is not a body the physics can hold: "" when it is made of valid closed solids (every shell
/// of every solid closed, each edge bounding two faces); else what is wrong, naming the first bad solid by
/// its index ("solid 2 is not closed (or not a valid solid)", "no solid (faces or shells only)").
std::string solid_problem(const Model& model);

/// Hex sha256 of bytes (rigger/base/sha256.hpp).
using rigger::sha256_hex;

}  // namespace rigger::cad
