#pragma once
/// @file
/// A tessellation for viewing: GLB written by OCCT's RWGltf_CafWriter, in metres and in the model's own
/// axes (no z-up to y-up rotation), one glTF primitive per B-rep face so that a picked triangle maps back
/// to its face.

#include "rigger/cad/model.hpp"

#include <Eigen/Core>

#include <cstdint>
#include <vector>

namespace rigger::cad {

struct TessellationOptions {
  double linear_deflection_m = 0.0;  ///< 0: 1/1000 of the bounding box diagonal, at least 10 µm
  double angular_deflection_rad = 0.5;
};

struct Tessellation {
  std::vector<std::uint8_t> glb;
  /// primitive_face[k]: the face index of primitive k of mesh 0 (faces without triangles have none).
  std::vector<int> primitive_face;
  std::size_t triangles = 0;
  double linear_deflection_m = 0.0;
};

/// Meshes the model (BRepMesh, stored in the shared B-rep) and writes it as GLB.
/// Throws CadError(kWriteFailed).
Tessellation tessellate(const Model& model, const TessellationOptions& options = {});

/// Meshes the model only (what tessellate() does before writing).
void mesh(const Model& model, const TessellationOptions& options = {});

/// Every face's triangles in one indexed mesh, metres, in the model's own axes; vertices are not shared
/// between faces (each face keeps its own, as BRepMesh makes them).
struct TriangleMesh {
  std::vector<Eigen::Vector3d> vertices_m;
  std::vector<Eigen::Vector3i> triangles;
};

/// Meshes the model and collects its triangles, wound as the faces are oriented.
/// Throws CadError(kWriteFailed) when OpenCascade fails.
TriangleMesh triangle_mesh(const Model& model, const TessellationOptions& options = {});

}  // namespace rigger::cad
