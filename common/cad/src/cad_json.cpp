#include "rigger/cad/cad_json.hpp"

#include <algorithm>

namespace rigger::cad {
namespace {

nlohmann::json vec(const Eigen::Vector3d& v) { return nlohmann::json::array({v.x(), v.y(), v.z()}); }

Eigen::Vector3d vec_from(const nlohmann::json& json, const char* what) {
  if (!json.is_array() || json.size() != 3 || !json[0].is_number() || !json[1].is_number() || !json[2].is_number()) {
    throw CadError(ErrorCode::kBadReference, std::string("reference: ") + what + " must be an array of 3 numbers");
  }
  return {json[0].get<double>(), json[1].get<double>(), json[2].get<double>()};
}

}  // namespace

nlohmann::json to_json(const ProductNode& product) {
  nlohmann::json node{{"name", product.name}, {"assembly", product.assembly}};
  if (!product.instance.empty()) node["instance"] = product.instance;
  if (!product.children.empty()) {
    node["children"] = nlohmann::json::array();
    for (const auto& child : product.children) {
      node["children"].push_back(to_json(child));
    }
  }
  return node;
}

nlohmann::json to_json(const Signature& signature) {
  return {{"type", signature.type},
          {"centroid_m", vec(signature.centroid_m)},
          {"direction", vec(signature.direction)},
          {"radius_m", signature.radius_m}};
}

nlohmann::json to_json(const Reference& reference) {
  return {{"model_sha256", reference.model_sha256},
          {"kind", std::string(to_string(reference.kind))},
          {"index", reference.index},
          {"signature", to_json(reference.signature)}};
}

nlohmann::json to_json(const Hole& hole) {
  return {{"index", hole.index},       {"faces", hole.faces},         {"axis", vec(hole.axis)},
          {"entry_m", vec(hole.entry_m)}, {"diameter_m", hole.diameter_m}, {"depth_m", hole.depth_m},
          {"through", hole.through}};
}

nlohmann::json to_json(const Eigen::Isometry3d& frame) {
  nlohmann::json rotation = nlohmann::json::array();
  for (int r = 0; r < 3; ++r) {
    rotation.push_back(nlohmann::json::array({frame.linear()(r, 0), frame.linear()(r, 1), frame.linear()(r, 2)}));
  }
  return {{"position_m", vec(frame.translation())},
          {"rotation", rotation},
          {"x", vec(frame.linear().col(0))},
          {"y", vec(frame.linear().col(1))},
          {"z", vec(frame.linear().col(2))}};
}

nlohmann::json features_json(const Features& features, bool entities) {
  nlohmann::json counts{
      {"solids", features.solids},
      {"faces", features.faces.size()},
      {"planar_faces", features.count_faces("plane")},
      {"cylindrical_faces", features.count_faces("cylinder")},
      {"other_faces", features.faces.size() -
                          static_cast<std::size_t>(features.count_faces("plane") + features.count_faces("cylinder"))},
      {"edges", features.edges.size()},
      {"line_edges", features.count_edges("line")},
      {"circular_edges", features.count_edges("circle")},
      {"faces_from_bspline",
       std::count_if(features.faces.begin(), features.faces.end(), [](const FaceInfo& f) { return f.recognised; })},
      {"edges_from_bspline",
       std::count_if(features.edges.begin(), features.edges.end(), [](const EdgeInfo& e) { return e.recognised; })},
      {"vertices", features.vertices.size()},
      {"holes", features.holes.size()}};
  nlohmann::json json{{"model_sha256", features.model_sha256}, {"units", "m"}, {"counts", counts}};
  json["holes"] = nlohmann::json::array();
  for (const auto& hole : features.holes) {
    json["holes"].push_back(to_json(hole));
  }
  if (!entities) {
    return json;
  }
  json["faces"] = nlohmann::json::array();
  for (const auto& face : features.faces) {
    nlohmann::json f{{"index", face.index}, {"signature", to_json(face.signature)}, {"area_m2", face.area_m2}};
    if (face.signature.type == "plane") {
      f["normal"] = vec(face.normal);
    }
    if (face.signature.type == "cylinder") {
      f["material_outside"] = face.material_outside;
    }
    if (face.recognised) {
      f["recognised_from"] = "bspline";
    }
    json["faces"].push_back(std::move(f));
  }
  json["edges"] = nlohmann::json::array();
  for (const auto& edge : features.edges) {
    nlohmann::json e{{"index", edge.index},
                     {"signature", to_json(edge.signature)},
                     {"length_m", edge.length_m},
                     {"start_m", vec(edge.start_m)},
                     {"end_m", vec(edge.end_m)}};
    if (edge.recognised) {
      e["recognised_from"] = "bspline";
    }
    json["edges"].push_back(std::move(e));
  }
  json["vertices"] = nlohmann::json::array();
  for (const auto& vertex : features.vertices) {
    json["vertices"].push_back({{"index", vertex.index}, {"point_m", vec(vertex.point_m)}});
  }
  return json;
}

nlohmann::json tessellation_json(const Features& features, const Tessellation& tessellation) {
  nlohmann::json parts = nlohmann::json::array();
  for (std::size_t k = 0; k < tessellation.primitive_face.size(); ++k) {
    const int face = tessellation.primitive_face[k];
    parts.push_back({{"primitive", k}, {"face", face}, {"ref", to_json(features.reference(EntityKind::kFace, face))}});
  }
  return {{"model_sha256", features.model_sha256},
          {"units", "m"},
          {"axes", "model (z up, not converted to glTF's y up)"},
          {"mesh", 0},
          {"triangles", tessellation.triangles},
          {"linear_deflection_m", tessellation.linear_deflection_m},
          {"parts", parts}};
}

Reference reference_from_json(const nlohmann::json& json) {
  if (!json.is_object()) {
    throw CadError(ErrorCode::kBadReference, "a reference must be a JSON object");
  }
  Reference reference;
  const std::string kind = json.value("kind", "");
  if (kind == "face") {
    reference.kind = EntityKind::kFace;
  } else if (kind == "edge") {
    reference.kind = EntityKind::kEdge;
  } else if (kind == "vertex") {
    reference.kind = EntityKind::kVertex;
  } else {
    throw CadError(ErrorCode::kBadReference, "reference: kind must be \"face\", \"edge\" or \"vertex\", not \"" + kind + "\"");
  }
  if (!json.contains("index") || !json["index"].is_number_integer()) {
    throw CadError(ErrorCode::kBadReference, "reference: index must be an integer");
  }
  reference.index = json["index"].get<int>();
  reference.model_sha256 = json.value("model_sha256", "");
  if (!json.contains("signature") || !json["signature"].is_object()) {
    throw CadError(ErrorCode::kBadReference, "reference: signature must be an object");
  }
  const auto& s = json["signature"];
  reference.signature.type = s.value("type", "");
  reference.signature.centroid_m = vec_from(s.value("centroid_m", nlohmann::json()), "signature.centroid_m");
  reference.signature.direction = vec_from(s.value("direction", nlohmann::json()), "signature.direction");
  if (!s.contains("radius_m") || !s["radius_m"].is_number()) {
    throw CadError(ErrorCode::kBadReference, "reference: signature.radius_m must be a number");
  }
  reference.signature.radius_m = s["radius_m"].get<double>();
  return reference;
}

}  // namespace rigger::cad
