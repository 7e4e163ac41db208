#include "rigger/cell_config/cell_cad.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <map>
#include <sstream>
#include <string>

#include "rigger/base/text.hpp"
#include "rigger/cad/features.hpp"
#include "rigger/cad/frames.hpp"
#include "static_overlap.hpp"

namespace rigger::cell {
namespace {

constexpr double kPi = 3.14159265358979323846;

struct LoadedModel {
  cad::Model model;
  cad::Features features;
  std::string step;  // as the cell file names it
};

std::string vector_text(const Eigen::Vector3d& v) {
  std::ostringstream out;
  out.precision(9);
  out << "[" << v.x() << ", " << v.y() << ", " << v.z() << "]";
  return out.str();
}

std::string cad_failure(const cad::CadError& error) {
  return std::string(cad::to_string(error.code())) + ": " + error.what();
}

// Derives the rules of one cell file; every failure is a CellFileError at the offending key.
class Deriver {
 public:
  Deriver(CellFile& file, std::filesystem::path model_dir, const cad::ReadLimits& limits)
      : file_(file), model_dir_(std::move(model_dir)), limits_(limits) {}

  CadDerivation run() {
    for (CellEntity& entity : file_.entities) {
      CadFeatures& features = entity.features;
      for (auto* list : {&features.grasp_frames, &features.approach_waypoints}) {
        for (NamedPose& named : *list) {
          if (named.cad) named.pose_entity_feature = derive_frame(entity, named.id, *named.cad);
        }
      }
      for (ScrewHole& hole : features.screw_holes) {
        if (hole.cad) hole.pose_entity_hole = derive_frame(entity, hole.id, *hole.cad);
      }
      if (features.insertion && features.insertion->cad) {
        features.insertion->pose_target_entity = derive_insertion(entity, *features.insertion);
      }
    }
    detail::check_static_solids_apart(file_, [this](const CellEntity& entity) -> const cad::Model& {
      return model_of(entity).model;
    });
    const auto total = std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
    stats_.derive_seconds = total - stats_.read_seconds;
    for (const auto& [id, loaded] : models_) stats_.read_models.emplace(id, loaded.model);
    return stats_;
  }

 private:
  // The entity's model, read and classified once.
  const LoadedModel& model_of(const CellEntity& entity) {
    const auto it = models_.find(entity.id);
    if (it != models_.end()) return it->second;
    const std::string pointer = entity.pointer + "/model/step";
    if (!entity.model || entity.model->step.empty()) {
      file_.fail(pointer, "a STEP model for the CAD features of \"" + entity.id + "\"", "nothing (missing key)");
    }
    const std::string& step = entity.model->step;
    const auto read_start = std::chrono::steady_clock::now();
    try {
      cad::Model model = cad::read_step_file(model_dir_ / step, limits_);
      if (const std::string stale = stale_model_problem(*entity.model, model.sha256()); !stale.empty()) {
        file_.fail(entity.pointer + "/model/sha256", "the pinned bytes of \"" + step + "\" for \"" + entity.id + "\"",
                   stale);
      }
      cad::Features features = cad::classify(model);
      stats_.read_seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - read_start).count();
      ++stats_.models;
      return models_.emplace(entity.id, LoadedModel{std::move(model), std::move(features), step}).first->second;
    } catch (const cad::CadError& error) {
      file_.fail(pointer,
                 "a readable STEP file \"" + step + "\" (relative to " + model_dir_.string() +
                     ") for the CAD features of \"" + entity.id + "\"",
                 cad_failure(error));
    }
  }

  // What a reference is in words, for errors: "feature \"grasp_side\" of \"load\": face 0 (plane at
  // [...]) of models/load.step".
  static std::string describe(const CellEntity& entity, const std::string& feature, const CadReference& ref,
                              const LoadedModel& model) {
    return "feature \"" + feature + "\" of \"" + entity.id + "\": " + ref.kind + " " + std::to_string(ref.index) +
           " of " + model.step + " matching its signature (" + ref.type + " at " + vector_text(ref.centroid_m) + " m)";
  }

  // The index `ref` designates in the model, checked against its signature.
  int resolve(const CellEntity& entity, const std::string& feature, const CadReference& ref,
              const LoadedModel& model) const {
    cad::Reference reference;
    reference.model_sha256 = model.features.model_sha256;
    reference.kind = ref.kind == "face" ? cad::EntityKind::kFace
                     : ref.kind == "edge" ? cad::EntityKind::kEdge
                                          : cad::EntityKind::kVertex;
    reference.index = ref.index;
    reference.signature.type = ref.type;
    reference.signature.centroid_m = ref.centroid_m;
    reference.signature.direction = ref.direction;
    reference.signature.radius_m = ref.radius_m;
    try {
      return cad::resolve(model.features, reference);
    } catch (const cad::CadError& error) {
      file_.fail(ref.pointer, describe(entity, feature, ref, model), cad_failure(error));
    }
  }

  // The face's frame at its centroid: origin there, z along the outward normal, x the model's x projected.
  static Eigen::Isometry3d face_frame(const LoadedModel& model, int face) {
    const cad::FaceInfo& info = model.features.faces[static_cast<std::size_t>(face)];
    return cad::frame_from_face(model.model, model.features, face, info.signature.centroid_m);
  }

  Eigen::Isometry3d derive_frame(const CellEntity& entity, const std::string& feature, CadRule& rule) {
    const LoadedModel& model = model_of(entity);
    Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
    try {
      if (rule.rule == CadRuleKind::kHole) {
        pose = hole_frame(entity, feature, rule, model);
      } else {
        pose = face_rule_frame(entity, feature, rule, model);
      }
    } catch (const cad::CadError& error) {
      file_.fail(rule.pointer, "a frame for feature \"" + feature + "\" of \"" + entity.id + "\" from " + model.step,
                 cad_failure(error));
    }
    rule.derived = true;
    ++stats_.features;
    return pose;
  }

  Eigen::Isometry3d hole_frame(const CellEntity& entity, const std::string& feature, const CadRule& rule,
                               const LoadedModel& model) const {
    return cad::frame_from_hole(model.features, hole_of(entity, feature, rule.face, model));
  }

  // The hole one of whose cylindrical faces `ref` designates.
  int hole_of(const CellEntity& entity, const std::string& feature, const CadReference& ref,
              const LoadedModel& model) const {
    const int face = resolve(entity, feature, ref, model);
    for (const cad::Hole& hole : model.features.holes) {
      for (const int hole_face : hole.faces) {
        if (hole_face == face) return hole.index;
      }
    }
    file_.fail(ref.pointer, describe(entity, feature, ref, model) + " being a face of a hole",
               "face " + std::to_string(face) + " is not part of a hole (a cylinder with the material outside that " +
                   "closes the full circle)");
  }

  Eigen::Isometry3d face_rule_frame(const CellEntity& entity, const std::string& feature, const CadRule& rule,
                                    const LoadedModel& model) const {
    const int face = resolve(entity, feature, rule.face, model);
    const Eigen::Isometry3d at_face = face_frame(model, face);
    const Eigen::Vector3d normal = at_face.linear().col(2);
    const Eigen::Vector3d z = rule.z_into ? Eigen::Vector3d(-normal) : normal;
    Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
    if (rule.x_edge) {
      const int edge = resolve(entity, feature, *rule.x_edge, model);
      const cad::EdgeInfo& info = model.features.edges[static_cast<std::size_t>(edge)];
      if (info.signature.type != "line") {
        file_.fail(rule.x_edge->pointer, describe(entity, feature, *rule.x_edge, model) + " being a straight line",
                   "edge " + std::to_string(edge) + " is a " + info.signature.type);
      }
      const Eigen::Vector3d x = (rule.x_reversed ? -1.0 : 1.0) * info.signature.direction.normalized();
      const double off_plane_rad = std::abs(std::asin(std::clamp(x.dot(z), -1.0, 1.0)));
      const cad::FrameTolerances tolerances;
      if (off_plane_rad > tolerances.perpendicular_rad) {
        std::ostringstream got;
        got.precision(6);
        got << "edge " << edge << " makes " << (kPi / 2 - off_plane_rad) * 180 / kPi << "° with the normal of face "
            << face << ", not 90° within " << tolerances.perpendicular_rad * 180 / kPi << "°";
        file_.fail(rule.x_edge->pointer,
                   describe(entity, feature, *rule.x_edge, model) + " perpendicular to the face's normal", got.str());
      }
      pose.linear() = cad::rotation_from_z(z, x);
    } else {
      pose.linear() = cad::rotation_from_z(z);
    }
    pose.translation() = at_face.translation() + rule.standoff_m * normal;
    return pose;
  }

  // The entity's pose in the target's frame when inserted: its mating face lies on the target's mating
  // face, normals opposite, the two faces' frames (x the model's x projected) aligned; then moved in the
  // face's plane (and, with two pins, turned about its normal) so that each pin's two hole axes coincide.
  Eigen::Isometry3d derive_insertion(const CellEntity& entity, Insertion& insertion) {
    CadRule& rule = *insertion.cad;
    const CellEntity& target = file_.require(insertion.target, "the insertion target");
    const LoadedModel& own = model_of(entity);
    const LoadedModel& other = model_of(target);
    const std::string feature = "insertion";
    Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
    try {
      const Eigen::Isometry3d pose_entity_face = face_frame(own, resolve(entity, feature, rule.face, own));
      const Eigen::Isometry3d pose_target_face = face_frame(other, resolve(entity, feature, *rule.target_face, other));
      const Eigen::Isometry3d half_turn_about_x(Eigen::AngleAxisd(kPi, Eigen::Vector3d::UnitX()));
      pose = pose_target_face * half_turn_about_x * pose_entity_face.inverse();
      if (!rule.pins.empty()) pose = pinned(entity, target, rule, pose, pose_target_face.linear().col(2));
    } catch (const cad::CadError& error) {
      file_.fail(rule.pointer, "mating faces for the insertion of \"" + entity.id + "\" into \"" + target.id + "\"",
                 cad_failure(error));
    }
    rule.derived = true;
    ++stats_.features;
    return pose;
  }

  // `pose` (the entity in the target's frame, faces mated; `normal` the target face's, target frame) moved
  // so that the pins' holes share their axes. A hole whose axis is not along the mating faces' normal, or
  // two pins whose holes are not as far apart on both parts, fail at the pin.
  Eigen::Isometry3d pinned(const CellEntity& entity, const CellEntity& target, const CadRule& rule,
                           Eigen::Isometry3d pose, const Eigen::Vector3d& normal) {
    constexpr double kAxisTolRad = 0.5 * kPi / 180.0;  // a hole's axis off the faces' normal
    constexpr double kSpanTolM = 5e-4;                 // the two pins' spans on the two parts
    const std::string feature = "insertion";
    const auto in_plane = [&](const Eigen::Vector3d& v) -> Eigen::Vector3d { return v - v.dot(normal) * normal; };
    struct Axis {
      Eigen::Vector3d entry;  // in the target's frame
      Eigen::Vector3d axis;
    };
    const auto axis_of = [&](const CellEntity& e, const LoadedModel& m, const CadReference& ref,
                             const Eigen::Isometry3d& to_target) {
      const cad::Hole& hole = m.features.holes[static_cast<std::size_t>(hole_of(e, feature, ref, m))];
      const Axis a{to_target * hole.entry_m, (to_target.linear() * hole.axis).normalized()};
      const double off = std::acos(std::min(1.0, std::abs(a.axis.dot(normal))));
      if (off > kAxisTolRad) {
        file_.fail(ref.pointer, describe(e, feature, ref, m) + " being a hole across the mating faces",
                   "its axis makes " + number_text(off * 180.0 / kPi) + "° with the faces' normal (at most " +
                       number_text(kAxisTolRad * 180.0 / kPi) + "°)");
      }
      return a;
    };
    const LoadedModel& own = model_of(entity);
    const LoadedModel& other = model_of(target);
    const auto pin_axes = [&](const CadPin& pin) {
      return std::make_pair(axis_of(entity, own, pin.hole, pose), axis_of(target, other, pin.target_hole,
                                                                          Eigen::Isometry3d::Identity()));
    };
    if (rule.pins.size() == 2) {
      const auto [own_1, target_1] = pin_axes(rule.pins[0]);
      const auto [own_2, target_2] = pin_axes(rule.pins[1]);
      const Eigen::Vector3d span_own = in_plane(own_2.entry - own_1.entry);
      const Eigen::Vector3d span_target = in_plane(target_2.entry - target_1.entry);
      if (span_own.norm() < kSpanTolM || std::abs(span_own.norm() - span_target.norm()) > kSpanTolM) {
        file_.fail(rule.pointer + "/pins/1",
                   "two pins as far apart on \"" + entity.id + "\" as on \"" + target.id + "\" (within " +
                       number_text(kSpanTolM * 1e3) + " mm)",
                   "their holes are " + number_text(span_own.norm() * 1e3) + " mm apart on \"" + entity.id + "\", " +
                       number_text(span_target.norm() * 1e3) + " mm on \"" + target.id + "\"");
      }
      const double turn = std::atan2(normal.dot(span_own.cross(span_target)), span_own.dot(span_target));
      pose = Eigen::Translation3d(own_1.entry) * Eigen::AngleAxisd(turn, normal) *
             Eigen::Translation3d(-own_1.entry) * pose;
    }
    const auto [own_1, target_1] = pin_axes(rule.pins[0]);
    return Eigen::Translation3d(in_plane(target_1.entry - own_1.entry)) * pose;
  }

  CellFile& file_;
  std::filesystem::path model_dir_;
  cad::ReadLimits limits_;
  std::map<std::string, LoadedModel> models_;  // entity id -> its model
  CadDerivation stats_;
  std::chrono::steady_clock::time_point start_ = std::chrono::steady_clock::now();
};

}  // namespace

CadDerivation derive_cad_features(CellFile& file, const std::filesystem::path& model_dir,
                                  const cad::ReadLimits& limits) {
  return Deriver(file, model_dir, limits).run();
}

CellFile load_cell_file_with_cad(const std::filesystem::path& path, CadDerivation* derivation) {
  CellFile file = load_cell_file(path);
  CadDerivation stats = derive_cad_features(file, cell_model_folder(path));
  if (derivation != nullptr) *derivation = std::move(stats);
  return file;
}

}  // namespace rigger::cell
