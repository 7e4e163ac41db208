#include "rigger/cad/tessellation.hpp"

#include <BRepBndLib.hxx>
#include <BRepMesh_IncrementalMesh.hxx>
#include <BRep_Builder.hxx>
#include <BRep_Tool.hxx>
#include <Bnd_Box.hxx>
#include <Message_ProgressRange.hxx>
#include <Poly_Triangulation.hxx>
#include <RWGltf_CafWriter.hxx>
#include <Standard_Failure.hxx>
#include <TColStd_IndexedDataMapOfStringString.hxx>
#include <TDataStd_Name.hxx>
#include <TDocStd_Document.hxx>
#include <TopExp.hxx>
#include <TopTools_IndexedMapOfShape.hxx>
#include <TopoDS.hxx>
#include <TopoDS_Compound.hxx>
#include <XCAFApp_Application.hxx>
#include <XCAFDoc_DocumentTool.hxx>
#include <XCAFDoc_ShapeTool.hxx>

#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <iterator>
#include <utility>

namespace rigger::cad {
namespace {

double deflection(const Model& model, const TessellationOptions& options) {
  if (options.linear_deflection_m > 0) {
    return options.linear_deflection_m;
  }
  Bnd_Box box;
  BRepBndLib::Add(model.shape(), box);
  const double diagonal = box.IsVoid() ? 0.0 : std::sqrt(box.SquareExtent());
  return std::max(1e-5, diagonal * 1e-3);
}

}  // namespace

void mesh(const Model& model, const TessellationOptions& options) {
  BRepMesh_IncrementalMesh mesher(model.shape(), deflection(model, options), false, options.angular_deflection_rad, true);
}

TriangleMesh triangle_mesh(const Model& model, const TessellationOptions& options) {
  TriangleMesh out;
  try {
    BRepMesh_IncrementalMesh mesher(model.shape(), deflection(model, options), false, options.angular_deflection_rad, true);
    TopTools_IndexedMapOfShape faces;
    TopExp::MapShapes(model.shape(), TopAbs_FACE, faces);
    for (int i = 1; i <= faces.Extent(); ++i) {
      const TopoDS_Face& face = TopoDS::Face(faces(i));
      TopLoc_Location location;
      const Handle(Poly_Triangulation) triangles = BRep_Tool::Triangulation(face, location);
      if (triangles.IsNull()) continue;
      const int base = static_cast<int>(out.vertices_m.size());
      for (int n = 1; n <= triangles->NbNodes(); ++n) {
        const gp_Pnt p = triangles->Node(n).Transformed(location.Transformation());
        out.vertices_m.emplace_back(p.X(), p.Y(), p.Z());
      }
      // A reversed face's triangles are stored with the surface's own orientation: flip them so that
      // every triangle faces out of the solid.
      const bool reversed = face.Orientation() == TopAbs_REVERSED;
      for (int t = 1; t <= triangles->NbTriangles(); ++t) {
        int a = 0, b = 0, c = 0;
        triangles->Triangle(t).Get(a, b, c);
        if (reversed) std::swap(b, c);
        out.triangles.emplace_back(base + a - 1, base + b - 1, base + c - 1);
      }
    }
  } catch (const Standard_Failure& failure) {
    throw CadError(ErrorCode::kWriteFailed,
                   "meshing model " + model.source() + " failed: " + failure.GetMessageString());
  }
  return out;
}

Tessellation tessellate(const Model& model, const TessellationOptions& options) {
  Tessellation result;
  result.linear_deflection_m = deflection(model, options);
  try {
    BRepMesh_IncrementalMesh mesher(model.shape(), result.linear_deflection_m, false, options.angular_deflection_rad, true);
    // One compound of the distinct faces in index order: RWGltf_CafWriter writes one primitive per face with
    // triangles, in this order, so primitive k maps back to a face index.
    TopTools_IndexedMapOfShape faces;
    TopExp::MapShapes(model.shape(), TopAbs_FACE, faces);
    TopoDS_Compound compound;
    BRep_Builder builder;
    builder.MakeCompound(compound);
    for (int i = 1; i <= faces.Extent(); ++i) {
      const TopoDS_Face& face = TopoDS::Face(faces(i));
      TopLoc_Location location;
      const Handle(Poly_Triangulation) triangles = BRep_Tool::Triangulation(face, location);
      if (triangles.IsNull() || triangles->NbTriangles() == 0) {
        continue;
      }
      builder.Add(compound, face);
      result.primitive_face.push_back(i - 1);
      result.triangles += static_cast<std::size_t>(triangles->NbTriangles());
    }
    Handle(TDocStd_Document) document;
    XCAFApp_Application::GetApplication()->NewDocument("MDTV-XCAF", document);
    XCAFDoc_DocumentTool::SetLengthUnit(document, 1.0);
    Handle(XCAFDoc_ShapeTool) shapes = XCAFDoc_DocumentTool::ShapeTool(document->Main());
    const TDF_Label label = shapes->AddShape(compound, false);
    TDataStd_Name::Set(label, TCollection_ExtendedString(model.product().name.c_str(), true));

    char path_template[] = "/tmp/rigger_cad_XXXXXX.glb";
    const int fd = ::mkstemps(path_template, 4);
    if (fd < 0) {
      throw CadError(ErrorCode::kWriteFailed, "cannot create a temporary GLB file in /tmp");
    }
    ::close(fd);
    const std::string path = path_template;
    RWGltf_CafWriter writer(path.c_str(), true);
    writer.ChangeCoordinateSystemConverter().SetInputLengthUnit(1.0);
    writer.SetMergeFaces(false);
    const bool written = writer.Perform(document, TColStd_IndexedDataMapOfStringString(), Message_ProgressRange());
    XCAFApp_Application::GetApplication()->Close(document);
    std::ifstream in(path, std::ios::binary);
    result.glb.assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
    ::unlink(path.c_str());
    if (!written || result.glb.empty()) {
      throw CadError(ErrorCode::kWriteFailed, "OCCT's glTF writer failed on model " + model.source());
    }
  } catch (const Standard_Failure& failure) {
    throw CadError(ErrorCode::kWriteFailed,
                   "tessellating model " + model.source() + " failed: " + failure.GetMessageString());
  }
  return result;
}

}  // namespace rigger::cad
