#pragma once
/// @file
/// The JSON shapes of rigger::cad results, shared by `riggerctl cad` and the rigger_cad service
/// (docs/cad.md documents them). Lengths in metres.

#include "rigger/cad/features.hpp"
#include "rigger/cad/tessellation.hpp"

#include <nlohmann/json.hpp>

namespace rigger::cad {

nlohmann::json to_json(const ProductNode& product);
nlohmann::json to_json(const Signature& signature);
nlohmann::json to_json(const Reference& reference);
nlohmann::json to_json(const Hole& hole);
/// {"position_m": [x,y,z], "rotation": [[...],[...],[...]] (rows), "x": [...], "y": [...], "z": [...]}
nlohmann::json to_json(const Eigen::Isometry3d& frame);

/// {"model_sha256", "counts": {...}, "holes": [...]} and, when `entities`, every face, edge and vertex.
nlohmann::json features_json(const Features& features, bool entities);

/// {"model_sha256", "units": "m", "mesh": 0, "triangles", "linear_deflection_m", "parts": [{"primitive",
/// "face", "ref"}]}
nlohmann::json tessellation_json(const Features& features, const Tessellation& tessellation);

/// A Reference from {"model_sha256", "kind", "index", "signature": {...}}; throws CadError(kBadReference).
Reference reference_from_json(const nlohmann::json& json);

}  // namespace rigger::cad
