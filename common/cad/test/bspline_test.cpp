// B-spline faces and edges that are planes, cylinders, lines and circles are classified as those: the same
// part written once with analytic geometry and once converted to B-splines gives the same holes, faces and
// signatures; a genuinely free-form face is not taken for one.

#include "rigger/cad/features.hpp"
#include "rigger/cad/model.hpp"
#include "rigger/cad/parts.hpp"
#include "step_file_test.hpp"

#include <gtest/gtest.h>
#include <BRepAdaptor_Surface.hxx>
#include <BRepBuilderAPI_MakeFace.hxx>
#include <BRepBuilderAPI_NurbsConvert.hxx>
#include <GeomConvert_ApproxSurface.hxx>
#include <Geom_BSplineSurface.hxx>
#include <Geom_CylindricalSurface.hxx>
#include <Geom_RectangularTrimmedSurface.hxx>
#include <TColStd_Array1OfInteger.hxx>
#include <TColStd_Array1OfReal.hxx>
#include <TColgp_Array2OfPnt.hxx>
#include <TopExp.hxx>
#include <TopTools_IndexedMapOfShape.hxx>
#include <TopoDS.hxx>

#include <cmath>

namespace rigger::cad {
namespace {

constexpr double kPi = 3.14159265358979323846;

using BsplineTest = StepFileTest;

// A plate with holes of three diameters: through and blind along z, one blind along -x from the side.
std::vector<parts::DrilledHole> two_diameter_holes() {
  const Eigen::Vector3d z = Eigen::Vector3d::UnitZ();
  return {{{0.030, 0.030, 0.012}, z, 0.008, 0.012, true},
          {{0.170, 0.030, 0.012}, z, 0.008, 0.012, true},
          {{0.100, 0.090, 0.012}, z, 0.008, 0.012, true},
          {{0.060, 0.080, 0.012}, z, 0.013, 0.006, false},
          {{0.140, 0.080, 0.012}, z, 0.013, 0.012, true},
          {{0.200, 0.060, 0.006}, Eigen::Vector3d::UnitX(), 0.004, 0.020, false}};
}

TopoDS_Shape to_bspline(const TopoDS_Shape& shape) {
  BRepBuilderAPI_NurbsConvert convert(shape, true);
  return convert.Shape();
}

int count_surfaces(const TopoDS_Shape& shape, GeomAbs_SurfaceType type) {
  TopTools_IndexedMapOfShape faces;
  TopExp::MapShapes(shape, TopAbs_FACE, faces);
  int n = 0;
  for (int i = 1; i <= faces.Extent(); ++i) {
    n += BRepAdaptor_Surface(TopoDS::Face(faces(i))).GetType() == type;
  }
  return n;
}

TEST_F(BsplineTest, ConvertedPlateHasTheHolesFacesAndSignaturesOfTheAnalyticOne) {
  const TopoDS_Shape analytic_shape = parts::drilled_box({0, 0, 0}, {0.2, 0.12, 0.012}, two_diameter_holes());
  const Model analytic_model = round_trip(analytic_shape, "analytic");
  const Model bspline_model = round_trip(to_bspline(analytic_shape), "bspline");
  // What was written is what is tested: every face of the converted file is read back as a B-spline.
  TopTools_IndexedMapOfShape read_faces;
  TopExp::MapShapes(bspline_model.shape(), TopAbs_FACE, read_faces);
  EXPECT_EQ(count_surfaces(bspline_model.shape(), GeomAbs_BSplineSurface), read_faces.Extent());

  const Features analytic = classify(analytic_model);
  const Features bspline = classify(bspline_model);
  ASSERT_EQ(analytic.holes.size(), two_diameter_holes().size());
  ASSERT_EQ(bspline.holes.size(), analytic.holes.size());
  EXPECT_EQ(bspline.count_faces("plane"), analytic.count_faces("plane"));
  EXPECT_EQ(bspline.count_faces("cylinder"), analytic.count_faces("cylinder"));
  EXPECT_EQ(bspline.count_faces("bspline"), 0);
  EXPECT_EQ(bspline.count_edges("line"), analytic.count_edges("line"));
  EXPECT_EQ(bspline.count_edges("circle"), analytic.count_edges("circle"));
  for (const auto& face : bspline.faces) {
    EXPECT_TRUE(face.recognised) << "face " << face.index << " is a " << face.signature.type;
  }
  for (const auto& face : analytic.faces) {
    EXPECT_FALSE(face.recognised) << "face " << face.index;
  }

  for (const auto& want : analytic.holes) {
    const Hole* found = nullptr;
    for (const auto& hole : bspline.holes) {
      if ((hole.entry_m - want.entry_m).norm() < 5e-5) {
        found = &hole;
      }
    }
    ASSERT_NE(found, nullptr) << "no hole at " << want.entry_m.transpose();
    EXPECT_LT(std::acos(std::min(1.0, found->axis.dot(want.axis))), 0.01 * kPi / 180) << found->axis.transpose();
    EXPECT_NEAR(found->diameter_m, want.diameter_m, 5e-5);
    EXPECT_NEAR(found->depth_m, want.depth_m, 5e-5);
    EXPECT_EQ(found->through, want.through);
  }

  // A reference taken on either file resolves on the other to an entity of the same type: a cell file
  // written against one works with the other.
  for (const auto& [from, to] : {std::pair{&analytic, &bspline}, std::pair{&bspline, &analytic}}) {
    for (const EntityKind kind : {EntityKind::kFace, EntityKind::kEdge}) {
      const std::size_t count = kind == EntityKind::kFace ? from->faces.size() : from->edges.size();
      for (std::size_t i = 0; i < count; ++i) {
        const Reference ref = from->reference(kind, static_cast<int>(i));
        int at = -1;
        EXPECT_NO_THROW(at = resolve(*to, ref)) << to_string(kind) << " " << i << " (" << ref.signature.type << ")";
        if (at >= 0) {
          EXPECT_EQ(to->signature(kind, at).type, ref.signature.type);
        }
      }
    }
  }
}

// A 100 x 100 mm B-spline patch whose four inner poles are raised 1 mm: curved both ways, so neither a plane
// nor a cylinder, though its straight borders are lines.
TopoDS_Face bumped_patch() {
  TColgp_Array2OfPnt poles(1, 4, 1, 4);
  for (int i = 1; i <= 4; ++i) {
    for (int j = 1; j <= 4; ++j) {
      const bool inner = i > 1 && i < 4 && j > 1 && j < 4;
      poles.SetValue(i, j, gp_Pnt(0.1 * (i - 1) / 3, 0.1 * (j - 1) / 3, inner ? 0.001 : 0.0));
    }
  }
  TColStd_Array1OfReal knots(1, 2);
  knots.SetValue(1, 0.0);
  knots.SetValue(2, 1.0);
  TColStd_Array1OfInteger multiplicities(1, 2);
  multiplicities.SetValue(1, 4);
  multiplicities.SetValue(2, 4);
  const Handle(Geom_BSplineSurface) surface =
      new Geom_BSplineSurface(poles, knots, knots, multiplicities, multiplicities, 3, 3);
  return BRepBuilderAPI_MakeFace(surface, 1e-7).Face();
}

TEST_F(BsplineTest, FreeformFaceIsNotTakenForAPlaneOrACylinder) {
  const Features features = classify(round_trip(bumped_patch(), "bump"));
  ASSERT_EQ(features.faces.size(), 1u);
  EXPECT_EQ(features.faces[0].signature.type, "bspline");
  EXPECT_FALSE(features.faces[0].recognised);
  EXPECT_EQ(features.count_edges("line"), 4);
}

// Exporters approximate a cylinder with a polynomial B-spline rather than convert it exactly (rational):
// OCCT 7.6's ShapeCustom_Surface::ConvertToAnalytical recognises only the exact form, the fit both.
TEST_F(BsplineTest, ApproximatedCylinderIsRecognised) {
  const gp_Ax3 frame(gp_Pnt(0.01, 0.02, 0.03), gp_Dir(0, 0.6, 0.8));
  const Handle(Geom_Surface) half_cylinder =
      new Geom_RectangularTrimmedSurface(new Geom_CylindricalSurface(frame, 0.005), 0.0, kPi, 0.0, 0.02);
  GeomConvert_ApproxSurface approximation(half_cylinder, 1e-7, GeomAbs_C2, GeomAbs_C2, 9, 9, 100, 0);
  ASSERT_TRUE(approximation.HasResult());
  ASSERT_FALSE(approximation.Surface()->IsURational());
  const Features features =
      classify(round_trip(BRepBuilderAPI_MakeFace(approximation.Surface(), 1e-7).Face(), "approx"));
  ASSERT_EQ(features.faces.size(), 1u);
  const FaceInfo& face = features.faces[0];
  EXPECT_EQ(face.signature.type, "cylinder");
  EXPECT_TRUE(face.recognised);
  EXPECT_NEAR(face.signature.radius_m, 0.005, 1e-6);
  EXPECT_LT(face.signature.direction.cross(Eigen::Vector3d(0, 0.6, 0.8)).norm(), 1e-4);
  EXPECT_NEAR(face.angle_rad, kPi, 1e-3);
  EXPECT_TRUE(features.holes.empty());  // half a cylinder is not a hole
}

}  // namespace
}  // namespace rigger::cad
