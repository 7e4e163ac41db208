#pragma once
// Internal: parses one entity of the cell file (its pose, camera, model and CAD features); references
// between entities are resolved by cell_file_from_json once every entity is known.

#include <initializer_list>
#include <map>
#include <string>
#include <string_view>
#include <vector>

#include "cell_checker.hpp"

namespace rigger::cell {

class EntityParser {
 public:
  explicit EntityParser(const Checker& check) : check_(check) {}

  CellEntity parse(const json& value, const std::string& pointer);

 private:
  CameraIntrinsics parse_camera(const json& value, const std::string& pointer) const;
  ObjectModel parse_model(const json& value, const std::string& pointer) const;
  CadFeatures parse_features(const json& value, const std::string& pointer, bool has_step);
  void claim_feature_id(const std::string& id, const std::string& pointer);
  const json& array(const json& value, const std::string& pointer) const;

  // A feature gives its pose either as numbers (`pose_key`) or as a rule over the STEP model ("cad"):
  // exactly one of them. Returns the "cad" value, or nullptr when the numbers are given.
  const json* pose_or_cad(const json& value, const std::string& pointer, std::string_view pose_key) const;

  CadReference parse_reference(const json& value, const std::string& pointer,
                               std::initializer_list<std::string_view> kinds) const;
  CadRule parse_cad_rule(const json& value, const std::string& pointer,
                         std::initializer_list<CadRuleKind> allowed) const;
  std::vector<NamedPose> parse_named_poses(const json& value, const std::string& pointer);
  std::vector<ScrewHole> parse_screw_holes(const json& value, const std::string& pointer);
  MarkerLayout parse_markers(const json& value, const std::string& pointer) const;
  CalibrationBoard parse_board(const json& value, const std::string& pointer) const;

  const Checker& check_;
  std::map<std::string, std::string> feature_ids_;  // id -> pointer of its first use
  bool has_step_ = false;                           // the entity being parsed has a STEP model
};

}  // namespace rigger::cell
