#pragma once
/// @file
/// A new version of an object's STEP model (the Planner's "Replace the model of…", docs/console.md): the
/// object keeps its id, pose and material; its model becomes the imported file, pinned by its sha256.
/// Every CAD rule that refers into the model — the object's grasp frames, approach waypoints, screw holes
/// and insertion, and the insertions of other objects into it — is checked against the new model as the
/// world model will resolve it (the same index with the same signature, or the one entity that has it),
/// by the CAD service. A rule that no longer resolves (a hole that moved, a face that went) is dropped
/// and named, to be declared again by picks; recipes made on the old model see their bindings stale.
/// Free of HTTP and DDS, unit-tested.
#include <functional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

namespace rigger::console {

/// POST /api/planner/replace: {"model": "sha256:<hex>" (an imported file), "object": "<entity id>", "comment"?}.
struct ReplaceRequest {
  std::string sha256;
  std::string object;
  std::string comment;
};
/// @throws PlannerError naming the field.
ReplaceRequest parse_replace_request(const nlohmann::json& body);

/// The model.step of the object's replacing model: "imported/<id>-<first 12 hex digits>.step".
std::string replaced_model_name(const std::string& id, const std::string& sha256);

/// A feature the new model no longer carries: "<entity>/<feature>" and why (the reference and what the
/// new model has there).
struct DroppedFeature {
  std::string feature;
  std::string why;
};

struct Replacement {
  nlohmann::json cell;                 ///< the document with the new model and without the dropped features
  std::vector<std::string> kept;       ///< "<entity>/<feature>" of the rules that still resolve
  std::vector<DroppedFeature> dropped;
};

/// Where references land on the new model, as the world model will resolve them (the CAD service's
/// `resolve` derivation, cad::resolve): for each reference, "" when it resolves, else why not.
using Resolver = std::function<std::vector<std::string>(const std::vector<nlohmann::json>& references)>;

/// The cell document `cell` with `request.object`'s model replaced by the imported file, whose references
/// `resolve` answers for, all at once.
/// @throws PlannerError at "/object" when the object is missing or has no STEP model, at "/model" when it
/// already has this model or `resolve` did not answer for every reference.
Replacement cell_with_replaced_model(const nlohmann::json& cell, const ReplaceRequest& request, const Resolver& resolve);

}  // namespace rigger::console
