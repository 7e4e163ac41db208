#pragma once
/// @file
/// A node of a STEP file's product tree (a part or a sub-assembly) as a STEP file of its own, and
/// assemblies written with OpenCascade (for tests and tools). docs/cad.md, "A node of an assembly".

#include "rigger/cad/model.hpp"

#include <Eigen/Geometry>

#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

namespace rigger::cad {

/// A node of a product tree by the index of the component taken at each level from the root (the
/// order of ProductNode::children): {} is the root, {1, 0} the first component of the root's second.
/// Two instances of the same part are two nodes.
using NodePath = std::vector<int>;

/// "1/0"; "" for the root.
std::string to_string(const NodePath& path);

/// A node extracted as a STEP file of its own.
struct ExtractedNode {
  /// The node's product (its sub-tree, names and the file's length unit kept) in the product's own frame,
  /// as STEP AP214 bytes: the same node of the same file gives the same bytes (a fixed header).
  std::string step;
  std::string name;      ///< the product's name (the instance's when the product has none)
  std::string instance;  ///< the instance's own name ("" for the root)
  /// The node's frame in the file's root frame (metres): where the file places this instance.
  Eigen::Isometry3d pose_in_file = Eigen::Isometry3d::Identity();
};

/// Extracts node `path` of STEP `bytes` (read like read_step_bytes, in a bounded child process unless
/// `limits.isolate` is false). Throws CadError: kBadReference for a path deeper than
/// limits.max_assembly_depth or naming a node that does not exist (the message says which level and how
/// many components it has), kNoGeometry for a node without a solid, else read_step_bytes' errors.
ExtractedNode extract_step_node(std::string_view bytes, const std::string& source, const NodePath& path,
                                const ReadLimits& limits = {});

/// The same for a STEP file on disk.
ExtractedNode extract_step_node(const std::filesystem::path& file, const NodePath& path, const ReadLimits& limits = {});

/// A product of an assembly to write: a part (its shape) or an assembly (its components).
struct AssemblyProduct {
  struct Component {
    std::string instance;  ///< the instance's name
    int product = 0;       ///< index into the products written; one product may be used many times
    Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();  ///< in the assembly's frame (metres)
  };
  std::string name;
  TopoDS_Shape shape_m;                ///< a part's shape in metres (null for an assembly)
  std::vector<Component> components;  ///< an assembly's components
};

/// Writes `products` (products[0] is the root; a component names a later product) as a STEP AP214 file
/// with their names, lengths in `unit` (OCCT's write.step.unit: "MM", "INCH", "M", ...). Throws
/// CadError(kWriteFailed).
void write_step_assembly(const std::vector<AssemblyProduct>& products, const std::filesystem::path& path,
                         const std::string& unit = "MM");

}  // namespace rigger::cad
