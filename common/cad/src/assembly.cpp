#include "rigger/cad/assembly.hpp"

#include "step_io.hpp"

#include <BRepBuilderAPI_Transform.hxx>
#include <Standard_Failure.hxx>
#include <Standard_OutOfMemory.hxx>
#include <TDF_LabelDataMap.hxx>
#include <TDF_LabelSequence.hxx>
#include <TDataStd_Name.hxx>
#include <TopExp_Explorer.hxx>
#include <XCAFApp_Application.hxx>
#include <XCAFDoc_DocumentTool.hxx>
#include <XCAFDoc_ShapeTool.hxx>
#include <gp_Quaternion.hxx>
#include <gp_Trsf.hxx>

#include <cstring>
#include <fstream>

namespace rigger::cad {
namespace {

void set_name(const TDF_Label& label, const std::string& name) {
  TDataStd_Name::Set(label, TCollection_ExtendedString(name.c_str(), true));
}

// The product a label stands for: the referred one of a component, else the label itself.
TDF_Label product_of(const TDF_Label& label) {
  TDF_Label product = label;
  if (XCAFDoc_ShapeTool::IsReference(label)) XCAFDoc_ShapeTool::GetReferredShape(label, product);
  return product;
}

// Copies product `product` (and, for an assembly, its components, each product once) into `to`, names
// and placements kept; the same source product gives the same copy (`done`).
TDF_Label copy_product(const TDF_Label& product, const Handle(XCAFDoc_ShapeTool) & to, TDF_LabelDataMap& done) {
  if (done.IsBound(product)) return done.Find(product);
  TDF_Label copy;
  if (XCAFDoc_ShapeTool::IsAssembly(product)) {
    copy = to->NewShape();
    TDF_LabelSequence components;
    XCAFDoc_ShapeTool::GetComponents(product, components, false);
    for (const TDF_Label& component : components) {
      const TDF_Label child = copy_product(product_of(component), to, done);
      const TDF_Label added = to->AddComponent(copy, child, XCAFDoc_ShapeTool::GetLocation(component));
      set_name(added, detail::label_name(component));
    }
  } else {
    copy = to->AddShape(XCAFDoc_ShapeTool::GetShape(product), false, false);
  }
  set_name(copy, detail::label_name(product));
  done.Bind(product, copy);
  return copy;
}

Eigen::Isometry3d to_isometry(const gp_Trsf& trsf, double unit_m) {
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) pose.linear()(r, c) = trsf.Value(r + 1, c + 1);
    pose.translation()(r) = trsf.TranslationPart().Coord(r + 1) * unit_m;
  }
  return pose;
}

gp_Trsf to_trsf(const Eigen::Isometry3d& pose, double scale) {
  gp_Trsf trsf;
  const Eigen::Quaterniond q(pose.linear());
  trsf.SetRotation(gp_Quaternion(q.x(), q.y(), q.z(), q.w()));
  const Eigen::Vector3d t = pose.translation() * scale;
  trsf.SetTranslationPart(gp_Vec(t.x(), t.y(), t.z()));
  return trsf;
}

// Extraction in this process: the node found level by level, copied into a new document with the file's
// unit, written with a fixed header.
std::string extract_in_process(std::string_view bytes, const std::string& source, const NodePath& path,
                               ExtractedNode& found) {
  const detail::StepDocument read(bytes, source);
  Handle(XCAFDoc_ShapeTool) shapes = XCAFDoc_DocumentTool::ShapeTool(read.document()->Main());
  TDF_LabelSequence roots;
  shapes->GetFreeShapes(roots);
  // Several top-level products: the root is the file, its components those products.
  std::vector<TDF_Label> node;  // the products the node stands for (the file's roots for its root)
  for (const TDF_Label& root : roots) node.push_back(root);
  TopLoc_Location location;
  found.name = roots.Length() == 1 ? detail::label_name(roots.Value(1)) : source;
  for (std::size_t level = 0; level < path.size(); ++level) {
    const std::string at = level == 0 ? "the root" : "node " + to_string(NodePath(path.begin(), path.begin() + static_cast<long>(level)));
    std::vector<TDF_Label> components;
    if (node.size() > 1) {
      components = node;
    } else if (XCAFDoc_ShapeTool::IsAssembly(node.front())) {
      TDF_LabelSequence sequence;
      XCAFDoc_ShapeTool::GetComponents(node.front(), sequence, false);
      for (const TDF_Label& component : sequence) components.push_back(component);
    }
    const int index = path[level];
    if (index < 0 || index >= static_cast<int>(components.size())) {
      throw CadError(ErrorCode::kBadReference,
                     "STEP input " + source + " has no node " + to_string(path) + ": " + at + " ('" + found.name + "') " +
                         (components.empty() ? std::string(XCAFDoc_ShapeTool::IsAssembly(node.front()) ? "has no components"
                                                                                                   : "is a part, without components")
                                             : "has " + std::to_string(components.size()) + " component" +
                                                   (components.size() == 1 ? "" : "s") + " (0 to " +
                                                   std::to_string(components.size() - 1) + ")"));
    }
    const TDF_Label& component = components[static_cast<std::size_t>(index)];
    if (XCAFDoc_ShapeTool::IsReference(component)) location = location * XCAFDoc_ShapeTool::GetLocation(component);
    found.instance = detail::label_name(component);
    node = {product_of(component)};
    found.name = detail::label_name(node.front());
    if (found.name.empty()) found.name = found.instance;
  }
  bool solid = false;
  for (const TDF_Label& product : node) solid = solid || TopExp_Explorer(XCAFDoc_ShapeTool::GetShape(product), TopAbs_SOLID).More();
  if (!solid) {
    throw CadError(ErrorCode::kNoGeometry, "STEP input " + source + ": node " +
                                               (path.empty() ? std::string("(the root)") : to_string(path)) + " ('" +
                                               found.name + "') holds no solid: only a solid can be an object");
  }
  found.pose_in_file = to_isometry(location.Transformation(), read.unit_m());
  Handle(TDocStd_Document) document;
  XCAFApp_Application::GetApplication()->NewDocument("MDTV-XCAF", document);
  XCAFDoc_DocumentTool::SetLengthUnit(document, read.unit_m());
  Handle(XCAFDoc_ShapeTool) to = XCAFDoc_DocumentTool::ShapeTool(document->Main());
  TDF_LabelDataMap done;
  for (const TDF_Label& product : node) copy_product(product, to, done);
  to->UpdateAssemblies();
  std::string step;
  try {
    step = detail::write_step_bytes(document, found.name + ".step", read.write_unit());
  } catch (...) {
    XCAFApp_Application::GetApplication()->Close(document);
    throw;
  }
  XCAFApp_Application::GetApplication()->Close(document);
  return step;
}

// The extracted node through the pipe from the child: name, instance, 12 numbers of the pose, the bytes.
void put_text(std::string& out, const std::string& text) {
  const auto size = static_cast<std::uint32_t>(text.size());
  out.append(reinterpret_cast<const char*>(&size), 4);
  out += text;
}

std::string get_text(std::string_view& in) {
  std::uint32_t size = 0;
  if (in.size() < 4) throw std::runtime_error("truncated");
  std::memcpy(&size, in.data(), 4);
  in.remove_prefix(4);
  if (in.size() < size) throw std::runtime_error("truncated");
  std::string text(in.substr(0, size));
  in.remove_prefix(size);
  return text;
}

std::string encode(const ExtractedNode& node) {
  std::string out;
  put_text(out, node.name);
  put_text(out, node.instance);
  const Eigen::Matrix<double, 3, 4> m = node.pose_in_file.affine();
  out.append(reinterpret_cast<const char*>(m.data()), sizeof(double) * 12);
  put_text(out, node.step);
  return out;
}

ExtractedNode decode(std::string_view in) {
  ExtractedNode node;
  node.name = get_text(in);
  node.instance = get_text(in);
  if (in.size() < sizeof(double) * 12) throw std::runtime_error("truncated");
  Eigen::Matrix<double, 3, 4> m;
  std::memcpy(m.data(), in.data(), sizeof(double) * 12);
  in.remove_prefix(sizeof(double) * 12);
  node.pose_in_file.affine() = m;
  node.step = get_text(in);
  return node;
}

}  // namespace

std::string to_string(const NodePath& path) {
  std::string text;
  for (std::size_t i = 0; i < path.size(); ++i) text += (i == 0 ? "" : "/") + std::to_string(path[i]);
  return text;
}

ExtractedNode extract_step_node(std::string_view bytes, const std::string& source, const NodePath& path,
                                const ReadLimits& limits) {
  if (path.size() > static_cast<std::size_t>(limits.max_assembly_depth)) {
    throw CadError(ErrorCode::kBadReference, "node path " + to_string(path).substr(0, 200) + " has " +
                                                 std::to_string(path.size()) + " levels, more than the limit of " +
                                                 std::to_string(limits.max_assembly_depth));
  }
  detail::check_step_bytes(bytes, source, limits);
  const auto work = [&] {
    try {
      ExtractedNode node;
      node.step = extract_in_process(bytes, source, path, node);
      return node;
    } catch (const Standard_OutOfMemory&) {
      throw CadError(ErrorCode::kCrashed, "extracting a node of STEP input " + source + " needed more than " +
                                              std::to_string(limits.max_memory_bytes >> 20) + " MiB of memory");
    } catch (const Standard_Failure& failure) {
      throw CadError(ErrorCode::kNotStep, "OCCT failed extracting node " + to_string(path) + " of STEP input " +
                                              source + ": " + failure.DynamicType()->Name() + " " +
                                              failure.GetMessageString());
    }
  };
  if (!limits.isolate) return work();
  const std::string answer = detail::run_isolated(source, limits, [&] { return encode(work()); });
  try {
    return decode(answer);
  } catch (const std::exception& error) {
    throw CadError(ErrorCode::kCrashed, "the STEP reader's answer for " + source + " is truncated: " + error.what());
  }
}

ExtractedNode extract_step_node(const std::filesystem::path& file, const NodePath& path, const ReadLimits& limits) {
  return extract_step_node(detail::read_bounded(file, limits), file.string(), path, limits);
}

void write_step_assembly(const std::vector<AssemblyProduct>& products, const std::filesystem::path& path,
                         const std::string& unit) {
  try {
    Handle(TDocStd_Document) document;
    XCAFApp_Application::GetApplication()->NewDocument("MDTV-XCAF", document);
    XCAFDoc_DocumentTool::SetLengthUnit(document, 1.0);
    Handle(XCAFDoc_ShapeTool) shapes = XCAFDoc_DocumentTool::ShapeTool(document->Main());
    // Leaves first: a component names a later product.
    std::vector<TDF_Label> labels(products.size());
    for (std::size_t i = products.size(); i-- > 0;) {
      const AssemblyProduct& product = products[i];
      if (product.components.empty()) {
        labels[i] = shapes->AddShape(product.shape_m, false, false);
      } else {
        labels[i] = shapes->NewShape();
        for (const AssemblyProduct::Component& c : product.components) {
          if (c.product <= static_cast<int>(i) || c.product >= static_cast<int>(products.size())) {
            throw CadError(ErrorCode::kWriteFailed, "cannot write " + path.string() + ": product " + product.name +
                                                        " names product " + std::to_string(c.product) +
                                                        ", not one after it");
          }
          const TDF_Label added = shapes->AddComponent(labels[i], labels[static_cast<std::size_t>(c.product)],
                                                       TopLoc_Location(to_trsf(c.pose, 1.0)));
          set_name(added, c.instance);
        }
      }
      set_name(labels[i], product.name);
    }
    shapes->UpdateAssemblies();
    const std::string step = detail::write_step_bytes(document, path.filename().string(), unit);
    XCAFApp_Application::GetApplication()->Close(document);
    std::ofstream out(path, std::ios::binary);
    out << step;
    if (!out) throw CadError(ErrorCode::kWriteFailed, "cannot write STEP file " + path.string());
  } catch (const Standard_Failure& failure) {
    throw CadError(ErrorCode::kWriteFailed,
                   "OCCT failed writing STEP file " + path.string() + ": " + failure.GetMessageString());
  }
}

}  // namespace rigger::cad
