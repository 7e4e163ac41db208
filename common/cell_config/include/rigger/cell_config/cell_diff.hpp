#pragma once
/// @file
/// What one cell document changes against another, by entity id: the world model's cell revisions
/// (rigger/world/cell changes_json) and `riggerctl cell diff`. Pure C++ over validated cell files.
///
/// The changes document (rigger/world/cell changes_json, riggerctl cell diff):
///   {"added":["id",...], "removed":["id",...],
///    "moved":[{"id","distance_m","angle_deg","parent_before","parent_after"}],
///    "changed":[{"id","keys":["model","features",...]}]}
/// "moved": the entity's pose in its tree's root frame differs (by more than 1 µm or 1 µrad), or its
/// parent does; an entity whose parent moved is moved too. "changed": a key of the entity's object in the
/// document other than its pose and parent differs (model, features, attributes, camera, localized, ...).

#include <set>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "rigger/cell_config/cell_file.hpp"

namespace rigger::cell {

/// Compares two validated cells. `before_doc` and `after_doc` are their JSON documents (the entities'
/// keys are compared there, so that every key the format has, now or later, counts).
nlohmann::json diff_cells(const CellFile& before, const nlohmann::json& before_doc, const CellFile& after,
                          const nlohmann::json& after_doc);

/// True when the changes document says nothing changed.
bool no_changes(const nlohmann::json& changes);

/// Ids the changes move, remove or change (not the added ones), sorted.
std::set<std::string> touched_entities(const nlohmann::json& changes);

/// Ids the changes move (their pose is then the revision's), sorted.
std::set<std::string> moved_entities(const nlohmann::json& changes);

/// "2 added, 1 moved" style summary; "no change" when empty.
std::string summarize_changes(const nlohmann::json& changes);

}  // namespace rigger::cell
