#include "entity_parser.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <set>
#include <utility>

namespace rigger::cell {

CellEntity EntityParser::parse(const json& value, const std::string& pointer) {
  check_.object(
      value, pointer,
      {"id", "kind", "parent", "pose", "localized", "attributes", "camera", "model", "features", "description",
       "calibration_board"});
  CellEntity entity;
  entity.pointer = pointer;
  entity.id = check_.identifier(check_.require(value, pointer, "id", "an entity id"), pointer + "/id");
  const std::string kind_text =
      check_.string(check_.require(value, pointer, "kind", "\"object\", \"device\" or \"frame\""), pointer + "/kind");
  const auto kind = entity_kind_from_string(kind_text);
  if (!kind) check_.fail(pointer + "/kind", "\"object\", \"device\" or \"frame\"", describe_json(value.at("kind")));
  entity.kind = *kind;

  if (const json* parent = Checker::find(value, "parent")) {
    entity.parent = check_.identifier(*parent, pointer + "/parent");
    if (entity.parent == entity.id) {
      check_.fail(pointer + "/parent", "the id of another entity", "the entity itself (\"" + entity.id + "\")");
    }
  } else if (entity.kind != EntityKind::kFrame) {
    check_.fail(pointer + "/parent", "a parent frame (only frames may be roots)", "nothing (missing key)");
  }

  if (const json* pose = Checker::find(value, "pose")) {
    if (entity.parent.empty())
      check_.fail(pointer + "/pose", "no pose on a root frame (it defines its own frame)", "a pose");
    entity.pose_parent_entity = check_.pose(*pose, pointer + "/pose");
  }

  // Calibrated devices and fixed frames are localized by the configuration; objects must be localized by
  // perception first unless the file says otherwise.
  entity.localized = entity.pose_parent_entity.has_value() && entity.kind != EntityKind::kObject;
  if (const json* localized = Checker::find(value, "localized")) {
    entity.localized = check_.boolean(*localized, pointer + "/localized");
    if (entity.localized && !entity.pose_parent_entity)
      check_.fail(pointer + "/localized", "false for an entity without a pose", "true");
  }

  if (const json* attributes = Checker::find(value, "attributes")) {
    if (!attributes->is_object()) check_.fail(pointer + "/attributes", "an object", describe_json(*attributes));
    check_.finite_everywhere(*attributes, pointer + "/attributes");
    entity.attributes = *attributes;
  }
  if (const json* description = Checker::find(value, "description")) {
    entity.attributes["description"] = check_.string(*description, pointer + "/description");
  }

  if (const json* camera = Checker::find(value, "camera")) {
    if (entity.kind != EntityKind::kDevice)
      check_.fail(pointer + "/camera", "camera intrinsics only on a device", kind_text);
    entity.camera = parse_camera(*camera, pointer + "/camera");
  }
  if (const json* model = Checker::find(value, "model")) {
    if (entity.kind != EntityKind::kObject)
      check_.fail(pointer + "/model", "an object model only on an object", kind_text);
    entity.model = parse_model(*model, pointer + "/model");
  }
  if (const json* features = Checker::find(value, "features")) {
    if (entity.kind == EntityKind::kFrame) check_.fail(pointer + "/features", "no features on a frame", "features");
    const bool has_step = entity.model && !entity.model->step.empty();
    entity.features = parse_features(*features, pointer + "/features", has_step);
  }
  if (const json* board = Checker::find(value, "calibration_board")) {
    if (entity.kind != EntityKind::kDevice)
      check_.fail(pointer + "/calibration_board", "a calibration board only on a device (a robot)", kind_text);
    entity.calibration_board = parse_board(*board, pointer + "/calibration_board");
  }
  return entity;
}

CalibrationBoard EntityParser::parse_board(const json& value, const std::string& pointer) const {
  check_.object(value, pointer, {"mount", "size_m", "markers"});
  CalibrationBoard board;
  board.pose_tool_board = check_.pose(
      check_.require(value, pointer, "mount", "the board's pose in the tool frame"), pointer + "/mount");
  board.size_m = check_.vector3(
      check_.require(value, pointer, "size_m", "[width, height, thickness] in metres"), pointer + "/size_m");
  if ((board.size_m.array() <= 0.0).any())
    check_.fail(pointer + "/size_m", "three extents > 0 m", describe_json(value.at("size_m")));
  board.markers = parse_markers(check_.require(value, pointer, "markers", "the board's markers"),
                                pointer + "/markers");
  if (board.markers.items.empty()) check_.fail(pointer + "/markers/items", "at least one marker", "none");
  // A marker lies on the printed face: at z = thickness / 2, facing out, inside the face's outline.
  constexpr double kTolerance_m = 1e-4;
  const double cos_tolerance = std::cos(0.5 * EIGEN_PI / 180.0);
  for (std::size_t i = 0; i < board.markers.items.size(); ++i) {
    const Marker& marker = board.markers.items[i];
    const Eigen::Vector3d centre = marker.pose_entity_marker.translation();
    const double half = 0.5 * marker.size_m;
    const bool on_face = std::abs(centre.z() - 0.5 * board.size_m.z()) <= kTolerance_m &&
                         marker.pose_entity_marker.linear().col(2).z() >= cos_tolerance &&
                         std::abs(centre.x()) + half <= 0.5 * board.size_m.x() + kTolerance_m &&
                         std::abs(centre.y()) + half <= 0.5 * board.size_m.y() + kTolerance_m;
    if (!on_face) {
      const std::string item_pointer = pointer + "/markers/items/" + std::to_string(i) + "/pose";
      check_.fail(item_pointer,
                  "a marker on the board's face (z = thickness / 2 = " + std::to_string(0.5 * board.size_m.z()) +
                      " m, facing +z, inside the " + std::to_string(board.size_m.x()) + " x " +
                      std::to_string(board.size_m.y()) + " m outline)",
                  "a marker at [" + std::to_string(centre.x()) + ", " + std::to_string(centre.y()) + ", " +
                      std::to_string(centre.z()) + "] m");
    }
  }
  return board;
}

CameraIntrinsics EntityParser::parse_camera(const json& value, const std::string& pointer) const {
  check_.object(
      value, pointer,
      {"width", "height", "fx", "fy", "cx", "cy", "distortion", "rate_hz", "noise_stddev", "optical_frame"});
  CameraIntrinsics camera;
  camera.width_px = static_cast<int>(check_.integer(
      check_.require(value, pointer, "width", "the image width in pixels"), pointer + "/width", 1, 65535));
  camera.height_px = static_cast<int>(check_.integer(
      check_.require(value, pointer, "height", "the image height in pixels"), pointer + "/height", 1, 65535));
  camera.fx_px = check_.positive(check_.require(value, pointer, "fx", "the focal length fx in pixels"), pointer + "/fx");
  camera.fy_px = check_.positive(check_.require(value, pointer, "fy", "the focal length fy in pixels"), pointer + "/fy");
  camera.cx_px =
      check_.number(check_.require(value, pointer, "cx", "the principal point cx in pixels"), pointer + "/cx");
  camera.cy_px =
      check_.number(check_.require(value, pointer, "cy", "the principal point cy in pixels"), pointer + "/cy");
  if (camera.cx_px < 0.0 || camera.cx_px > camera.width_px) {
    check_.fail(pointer + "/cx", "a principal point inside the image [0, width]", describe_json(value.at("cx")));
  }
  if (camera.cy_px < 0.0 || camera.cy_px > camera.height_px) {
    check_.fail(pointer + "/cy", "a principal point inside the image [0, height]", describe_json(value.at("cy")));
  }
  camera.rate_hz =
      check_.positive(check_.require(value, pointer, "rate_hz", "the frame rate in Hz"), pointer + "/rate_hz");
  if (const json* distortion = Checker::find(value, "distortion")) {
    camera.distortion = check_.numbers(*distortion, pointer + "/distortion", {4, 5, 8, 12, 14},
                                       "an array of 4, 5, 8, 12 or 14 numbers (OpenCV distortion coefficients)");
  }
  if (const json* noise = Checker::find(value, "noise_stddev")) {
    camera.noise_stddev = check_.number(*noise, pointer + "/noise_stddev");
    if (camera.noise_stddev < 0.0) check_.fail(pointer + "/noise_stddev", "a number >= 0", describe_json(*noise));
  }
  if (const json* optical = Checker::find(value, "optical_frame")) {
    camera.optical_frame = check_.string(*optical, pointer + "/optical_frame");
  }
  return camera;
}

ObjectModel EntityParser::parse_model(const json& value, const std::string& pointer) const {
  check_.object(value, pointer, {"shape", "size_m", "mass_kg", "density_kg_m3", "frame", "static", "step", "sha256"});
  ObjectModel model;
  if (const json* step = Checker::find(value, "step")) {
    model.step = check_.string(*step, pointer + "/step");
    if (model.step.empty()) check_.fail(pointer + "/step", "a STEP file path", "an empty string");
  }
  if (const json* sha256 = Checker::find(value, "sha256")) {
    if (model.step.empty()) check_.fail(pointer + "/sha256", "a STEP model (\"step\") whose bytes it pins");
    model.step_sha256 = check_.string(*sha256, pointer + "/sha256");
    std::transform(model.step_sha256.begin(), model.step_sha256.end(), model.step_sha256.begin(),
                   [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
    if (model.step_sha256.size() != 64 ||
        model.step_sha256.find_first_not_of("0123456789abcdef") != std::string::npos) {
      check_.fail(pointer + "/sha256", "64 hex digits (the sha256 of the STEP file's bytes)", describe_json(*sha256));
    }
  }
  // Geometry: the box shorthand, or the STEP model's solids alone.
  if (const json* shape = Checker::find(value, "shape")) {
    model.shape = check_.string(*shape, pointer + "/shape");
    if (model.shape != "box") check_.fail(pointer + "/shape", "\"box\"", describe_json(*shape));
    model.size_m =
        check_.vector3(check_.require(value, pointer, "size_m", "[x, y, z] extents in metres"), pointer + "/size_m");
    if ((model.size_m.array() <= 0.0).any()) {
      check_.fail(pointer + "/size_m", "three extents > 0 m", describe_json(value.at("size_m")));
    }
  } else if (model.step.empty()) {
    check_.fail(pointer, "a geometry: \"shape\": \"box\" with \"size_m\", or a STEP model (\"step\")",
                "neither");
  } else if (Checker::find(value, "size_m") != nullptr) {
    check_.fail(pointer + "/size_m", "no size_m without \"shape\": \"box\" (the STEP model gives the size)");
  }
  if (const json* mass = Checker::find(value, "mass_kg"))
    model.mass_kg = check_.positive(*mass, pointer + "/mass_kg");
  if (const json* density = Checker::find(value, "density_kg_m3")) {
    if (model.mass_kg) check_.fail(pointer + "/density_kg_m3", "either mass_kg or density_kg_m3, not both");
    if (model.step.empty()) check_.fail(pointer + "/density_kg_m3", "a STEP model (\"step\") whose volume it weighs");
    model.density_kg_m3 = check_.positive(*density, pointer + "/density_kg_m3");
  }
  if (const json* frame = Checker::find(value, "frame")) model.frame = check_.string(*frame, pointer + "/frame");
  if (const json* is_static = Checker::find(value, "static"))
    model.is_static = check_.boolean(*is_static, pointer + "/static");
  return model;
}

CadFeatures EntityParser::parse_features(const json& value, const std::string& pointer, bool has_step) {
  has_step_ = has_step;
  check_.object(value, pointer,
                {"rope_attachment", "grasp_frames", "approach_waypoints", "markers", "insertion", "screw_holes"});
  CadFeatures features;
  feature_ids_.clear();
  if (const json* rope = Checker::find(value, "rope_attachment")) {
    features.rope_attachment = check_.pose(*rope, pointer + "/rope_attachment");
    feature_ids_.emplace("rope_attachment", pointer + "/rope_attachment");
  }
  if (const json* grasps = Checker::find(value, "grasp_frames")) {
    features.grasp_frames = parse_named_poses(*grasps, pointer + "/grasp_frames");
  }
  if (const json* waypoints = Checker::find(value, "approach_waypoints")) {
    features.approach_waypoints = parse_named_poses(*waypoints, pointer + "/approach_waypoints");
  }
  if (const json* holes = Checker::find(value, "screw_holes")) {
    features.screw_holes = parse_screw_holes(*holes, pointer + "/screw_holes");
  }
  if (const json* markers = Checker::find(value, "markers")) {
    features.markers = parse_markers(*markers, pointer + "/markers");
  }
  if (const json* insertion = Checker::find(value, "insertion")) {
    const std::string insertion_pointer = pointer + "/insertion";
    check_.object(*insertion, insertion_pointer, {"target", "pose_in_target", "cad"});
    Insertion result;
    result.target = check_.identifier(check_.require(*insertion, insertion_pointer, "target", "the target entity id"),
                                      insertion_pointer + "/target");
    if (const json* rule = pose_or_cad(*insertion, insertion_pointer, "pose_in_target")) {
      result.cad = parse_cad_rule(*rule, insertion_pointer + "/cad", {CadRuleKind::kMateFaces});
    } else {
      result.pose_target_entity = check_.pose(insertion->at("pose_in_target"), insertion_pointer + "/pose_in_target");
    }
    features.insertion = result;
  }
  return features;
}

void EntityParser::claim_feature_id(const std::string& id, const std::string& pointer) {
  const auto [it, inserted] = feature_ids_.emplace(id, pointer);
  if (!inserted)
    check_.fail(pointer, "a feature id unique within the entity", "\"" + id + "\", already used at " + it->second);
}

const json& EntityParser::array(const json& value, const std::string& pointer) const {
  if (!value.is_array()) check_.fail(pointer, "an array", describe_json(value));
  return value;
}

const json* EntityParser::pose_or_cad(const json& value, const std::string& pointer, std::string_view pose_key) const {
  const json* pose = Checker::find(value, pose_key);
  const json* rule = Checker::find(value, "cad");
  const std::string expected =
      "either \"" + std::string(pose_key) + "\" (numbers) or \"cad\" (a rule over the STEP model)";
  if (pose == nullptr && rule == nullptr) check_.fail(join_pointer(pointer, pose_key), expected, "neither");
  if (pose != nullptr && rule != nullptr) check_.fail(pointer + "/cad", expected, "both");
  if (rule != nullptr && !has_step_) {
    check_.fail(pointer + "/cad", "a CAD rule only on an object whose model names a STEP file (model.step)",
                "an object without one");
  }
  return rule;
}

CadReference EntityParser::parse_reference(const json& value, const std::string& pointer,
                                         std::initializer_list<std::string_view> kinds) const {
  check_.object(value, pointer, {"kind", "index", "signature"});
  CadReference ref;
  ref.pointer = pointer;
  std::string kind_names;
  for (const auto kind : kinds) kind_names += (kind_names.empty() ? "\"" : " or \"") + std::string(kind) + "\"";
  ref.kind = check_.string(check_.require(value, pointer, "kind", kind_names), pointer + "/kind");
  if (std::find(kinds.begin(), kinds.end(), ref.kind) == kinds.end()) {
    check_.fail(pointer + "/kind", kind_names, describe_json(value.at("kind")));
  }
  ref.index = static_cast<int>(check_.integer(
      check_.require(value, pointer, "index", "the " + ref.kind + "'s index in the model (from 0)"),
      pointer + "/index", 0, 1'000'000));
  const std::string sig_pointer = pointer + "/signature";
  const json& signature = check_.require(value, pointer, "signature",
                                         "the " + ref.kind + "'s signature (riggerctl cad inspect --json --entities)");
  check_.object(signature, sig_pointer, {"type", "centroid_m", "direction", "radius_m"});
  ref.type = check_.string(check_.require(signature, sig_pointer, "type", "a signature type such as \"plane\""),
                           sig_pointer + "/type");
  ref.centroid_m = check_.vector3(check_.require(signature, sig_pointer, "centroid_m", "[x, y, z] in metres"),
                                  sig_pointer + "/centroid_m");
  ref.direction = check_.vector3(check_.require(signature, sig_pointer, "direction", "a direction [x, y, z]"),
                                 sig_pointer + "/direction");
  ref.radius_m = check_.number(check_.require(signature, sig_pointer, "radius_m", "a radius in metres (0: none)"),
                               sig_pointer + "/radius_m");
  return ref;
}

CadRule EntityParser::parse_cad_rule(const json& value, const std::string& pointer,
                                   std::initializer_list<CadRuleKind> allowed) const {
  check_.object(value, pointer,
                {"rule", "face", "hole", "z", "x_edge", "x_reversed", "standoff_m", "target_face", "pins"});
  std::string rule_names;
  for (const CadRuleKind kind : allowed) {
    const char* name = kind == CadRuleKind::kFace ? "face" : kind == CadRuleKind::kHole ? "hole" : "mate_faces";
    rule_names += (rule_names.empty() ? "\"" : " or \"") + std::string(name) + "\"";
  }
  const json& rule_value = check_.require(value, pointer, "rule", rule_names);
  const auto kind = cad_rule_from_string(check_.string(rule_value, pointer + "/rule"));
  if (!kind || std::find(allowed.begin(), allowed.end(), *kind) == allowed.end()) {
    check_.fail(pointer + "/rule", rule_names + " here", describe_json(rule_value));
  }
  CadRule rule;
  rule.rule = *kind;
  rule.pointer = pointer;
  // Keys that belong to another rule are refused: a rule must not carry settings it ignores.
  const auto only_for = [&](std::string_view key, CadRuleKind owner, const char* owner_name) {
    if (Checker::find(value, key) != nullptr && rule.rule != owner) {
      check_.fail(join_pointer(pointer, key), "\"" + std::string(key) + "\" only in a \"" + owner_name + "\" rule",
                  describe_json(rule_value));
    }
  };
  only_for("hole", CadRuleKind::kHole, "hole");
  for (const auto key : {"face", "z", "x_edge", "x_reversed", "standoff_m"}) {
    if (rule.rule == CadRuleKind::kMateFaces && std::string_view(key) == "face") continue;
    only_for(key, CadRuleKind::kFace, "face");
  }
  only_for("target_face", CadRuleKind::kMateFaces, "mate_faces");
  only_for("pins", CadRuleKind::kMateFaces, "mate_faces");
  switch (rule.rule) {
    case CadRuleKind::kHole:
      rule.face = parse_reference(check_.require(value, pointer, "hole", "a cylindrical face of the hole"),
                                  pointer + "/hole", {"face"});
      break;
    case CadRuleKind::kFace:
      rule.face = parse_reference(check_.require(value, pointer, "face", "a face reference"), pointer + "/face",
                                  {"face"});
      if (const json* z = Checker::find(value, "z")) {
        const std::string z_text = check_.string(*z, pointer + "/z");
        if (z_text != "out" && z_text != "into") check_.fail(pointer + "/z", "\"out\" or \"into\"", describe_json(*z));
        rule.z_into = z_text == "into";
      }
      if (const json* edge = Checker::find(value, "x_edge")) {
        rule.x_edge = parse_reference(*edge, pointer + "/x_edge", {"edge"});
      }
      if (const json* reversed = Checker::find(value, "x_reversed")) {
        if (!rule.x_edge) check_.fail(pointer + "/x_reversed", "x_reversed only with an x_edge", "no x_edge");
        rule.x_reversed = check_.boolean(*reversed, pointer + "/x_reversed");
      }
      if (const json* standoff = Checker::find(value, "standoff_m")) {
        rule.standoff_m = check_.number(*standoff, pointer + "/standoff_m");
      }
      break;
    case CadRuleKind::kMateFaces:
      rule.face = parse_reference(check_.require(value, pointer, "face", "this object's mating face"),
                                  pointer + "/face", {"face"});
      rule.target_face = parse_reference(
          check_.require(value, pointer, "target_face", "the target's mating face (in the target's STEP model)"),
          pointer + "/target_face", {"face"});
      if (const json* pins = Checker::find(value, "pins")) {
        const std::string pins_pointer = pointer + "/pins";
        if (!pins->is_array() || pins->empty() || pins->size() > 2) {
          check_.fail(pins_pointer, "one or two pins: [{\"hole\", \"target_hole\"}, ...]", describe_json(*pins));
        }
        for (std::size_t i = 0; i < pins->size(); ++i) {
          const std::string pin_pointer = pins_pointer + "/" + std::to_string(i);
          const json& pin = (*pins)[i];
          check_.object(pin, pin_pointer, {"hole", "target_hole"});
          rule.pins.push_back(
              {parse_reference(check_.require(pin, pin_pointer, "hole", "a cylindrical face of this object's hole"),
                               pin_pointer + "/hole", {"face"}),
               parse_reference(check_.require(pin, pin_pointer, "target_hole",
                                              "a cylindrical face of the target's hole (in the target's STEP model)"),
                               pin_pointer + "/target_hole", {"face"})});
        }
      }
      break;
  }
  return rule;
}

std::vector<NamedPose> EntityParser::parse_named_poses(const json& value, const std::string& pointer) {
  std::vector<NamedPose> result;
  for (std::size_t i = 0; i < array(value, pointer).size(); ++i) {
    const std::string item_pointer = pointer + "/" + std::to_string(i);
    check_.object(value[i], item_pointer, {"id", "pose", "cad"});
    NamedPose named;
    named.id = check_.identifier(check_.require(value[i], item_pointer, "id", "a feature id"), item_pointer + "/id");
    claim_feature_id(named.id, item_pointer + "/id");
    if (const json* rule = pose_or_cad(value[i], item_pointer, "pose")) {
      named.cad = parse_cad_rule(*rule, item_pointer + "/cad", {CadRuleKind::kFace, CadRuleKind::kHole});
    } else {
      named.pose_entity_feature = check_.pose(value[i].at("pose"), item_pointer + "/pose");
    }
    result.push_back(named);
  }
  return result;
}

std::vector<ScrewHole> EntityParser::parse_screw_holes(const json& value, const std::string& pointer) {
  std::vector<ScrewHole> result;
  for (std::size_t i = 0; i < array(value, pointer).size(); ++i) {
    const std::string item_pointer = pointer + "/" + std::to_string(i);
    check_.object(value[i], item_pointer, {"id", "pose", "cad", "screw_type", "torque_nm"});
    ScrewHole hole;
    hole.id = check_.identifier(check_.require(value[i], item_pointer, "id", "a feature id"), item_pointer + "/id");
    claim_feature_id(hole.id, item_pointer + "/id");
    if (const json* rule = pose_or_cad(value[i], item_pointer, "pose")) {
      hole.cad = parse_cad_rule(*rule, item_pointer + "/cad", {CadRuleKind::kHole});
    } else {
      hole.pose_entity_hole = check_.pose(value[i].at("pose"), item_pointer + "/pose");
    }
    hole.screw_type =
        check_.string(check_.require(value[i], item_pointer, "screw_type", "a screw type such as \"M12x40\""),
                      item_pointer + "/screw_type");
    if (hole.screw_type.empty()) check_.fail(item_pointer + "/screw_type", "a non-empty screw type", "\"\"");
    hole.torque_nm = check_.positive(check_.require(value[i], item_pointer, "torque_nm", "the torque in N m"),
                                     item_pointer + "/torque_nm");
    result.push_back(hole);
  }
  return result;
}

MarkerLayout EntityParser::parse_markers(const json& value, const std::string& pointer) const {
  check_.object(value, pointer, {"dictionary", "items"});
  MarkerLayout layout;
  layout.dictionary = check_.string(check_.require(value, pointer, "dictionary", "an ArUco dictionary name"),
                                    pointer + "/dictionary");
  const auto dictionary = marker_dictionary(layout.dictionary);
  if (!dictionary) {
    check_.fail(pointer + "/dictionary", "an OpenCV predefined dictionary such as \"DICT_4X4_50\"",
                describe_json(value.at("dictionary")));
  }
  const json& items = array(check_.require(value, pointer, "items", "an array of markers"), pointer + "/items");
  std::set<std::int64_t> ids;
  for (std::size_t i = 0; i < items.size(); ++i) {
    const std::string item_pointer = pointer + "/items/" + std::to_string(i);
    check_.object(items[i], item_pointer, {"id", "size_m", "pose"});
    Marker marker;
    marker.id = static_cast<int>(check_.integer(check_.require(items[i], item_pointer, "id", "a marker id"),
                                                item_pointer + "/id", 0, dictionary->size - 1));
    if (!ids.insert(marker.id).second) {
      check_.fail(item_pointer + "/id", "a marker id unique within the layout", std::to_string(marker.id));
    }
    marker.size_m = check_.positive(check_.require(items[i], item_pointer, "size_m", "the marker side in metres"),
                                    item_pointer + "/size_m");
    marker.pose_entity_marker =
        check_.pose(check_.require(items[i], item_pointer, "pose", "a pose"), item_pointer + "/pose");
    layout.items.push_back(marker);
  }
  return layout;
}
}  // namespace rigger::cell
