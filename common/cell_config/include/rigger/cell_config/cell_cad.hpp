#pragma once
/// @file
/// The cell file's CAD features derived from the objects' STEP models (rigger_cell_cad, over
/// common/cad and OpenCascade). A feature given by a rule ("cad": face, hole, mate_faces; format in
/// docs/world-model.md) names faces and edges of its object's model by index and signature; this reads
/// each model named by a rule once (bounded, in a child process), checks every reference against the
/// model and fills in the poses. The one place where rule → numbers happens: the world model, the
/// simulated cell and the tests all call it, so they all get the same numbers.

#include <filesystem>
#include <map>
#include <string>

#include "rigger/cad/model.hpp"
#include "rigger/cell_config/cell_file.hpp"

namespace rigger::cell {

/// What a derivation did, for the start-up log.
struct CadDerivation {
  int models = 0;            ///< STEP models read
  int features = 0;          ///< CAD rules derived
  double read_seconds = 0.0;      ///< reading and classifying the models (wall time)
  double derive_seconds = 0.0;    ///< resolving the references and building the frames
  /// The STEP models read, by entity id (copies share the B-rep): for readers that need the geometry too.
  std::map<std::string, cad::Model> read_models;
};

/// Derives every CAD rule of `file` (features.*.cad) from the STEP models of its objects; model paths
/// (model.step) are relative to `model_dir` (the cell file's folder). Sets the rules' poses and marks them
/// derived; features given as numbers are left as they are.
/// @throws CellFileError naming the file, the JSON pointer of the offending key and the object and feature:
///   at ".../model/step" for a missing, unreadable or invalid STEP file; at the reference
///   (".../cad/face", ".../cad/x_edge", ".../cad/hole", ".../cad/target_face") for an index that does not
///   exist, a signature that no longer matches the model (CAD_STALE_REFERENCE: the model changed), or picks
///   that make no frame; at ".../pose" for a static object given by its STEP model whose solid overlaps
///   another static object (they may touch; sharing more than 1 cm³ is refused).
CadDerivation derive_cad_features(CellFile& file, const std::filesystem::path& model_dir,
                                  const cad::ReadLimits& limits = {});

/// load_cell_file(path), then derive_cad_features relative to the file's folder.
/// @throws CellFileError as both.
CellFile load_cell_file_with_cad(const std::filesystem::path& path, CadDerivation* derivation = nullptr);

}  // namespace rigger::cell
