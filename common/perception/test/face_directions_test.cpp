// The search's start from the faces seen: dominant normal directions and their planes, orientations that turn
// a model's directions onto an image's, and positions that put the matched planes on the image's.
#include "face_directions.hpp"

#include <gtest/gtest.h>

#include <vector>

namespace rigger::perception::detail {
namespace {

double angle_deg(const Eigen::Matrix3d& a, const Eigen::Matrix3d& b) {
  return Eigen::AngleAxisd(a.transpose() * b).angle() * 180.0 / M_PI;
}

/// Points on the faces of a 0.4 x 0.3 x 0.2 m box about the origin, `per_face` on each (object frame).
void box_faces(int per_face, std::vector<Eigen::Vector3d>& points, std::vector<Eigen::Vector3d>& normals) {
  const Eigen::Vector3d half(0.2, 0.15, 0.1);
  for (int axis = 0; axis < 3; ++axis) {
    for (const double sign : {1.0, -1.0}) {
      for (int i = 0; i < per_face; ++i) {
        Eigen::Vector3d p = Eigen::Vector3d::Zero();
        p[(axis + 1) % 3] = half[(axis + 1) % 3] * (2.0 * ((i * 7) % per_face) / per_face - 1.0);
        p[(axis + 2) % 3] = half[(axis + 2) % 3] * (2.0 * ((i * 13) % per_face) / per_face - 1.0);
        p[axis] = sign * half[axis];
        points.push_back(p);
        normals.push_back(sign * Eigen::Vector3d::Unit(axis));
      }
    }
  }
}

TEST(FaceDirections, FindsEachFaceOfABoxWithItsPlane) {
  std::vector<Eigen::Vector3d> points;
  std::vector<Eigen::Vector3d> normals;
  box_faces(50, points, normals);
  const std::vector<FaceDirection> faces = face_directions(points, normals, 0.05, 12);
  ASSERT_EQ(faces.size(), 6U);
  for (const FaceDirection& face : faces) {
    EXPECT_NEAR(face.share, 1.0 / 6.0, 1e-9);
    ASSERT_EQ(face.offsets_m.size(), 1U);
    int axis = 0;
    face.normal.cwiseAbs().maxCoeff(&axis);
    EXPECT_NEAR(face.normal.cwiseAbs()[axis], 1.0, 1e-9);
    EXPECT_NEAR(face.offsets_m.front(), Eigen::Vector3d(0.2, 0.15, 0.1)[axis], 1e-9);
  }
  // Directions under the share are none.
  EXPECT_TRUE(face_directions(points, normals, 0.2, 12).empty());
}

TEST(FaceDirections, TurnsAndPlacesTheModelOntoTwoFacesSeen) {
  std::vector<Eigen::Vector3d> points;
  std::vector<Eigen::Vector3d> normals;
  box_faces(50, points, normals);
  const std::vector<FaceDirection> model = face_directions(points, normals, 0.05, 12);
  // The box seen by a camera (object to camera): its +x and +z faces toward it, 2 and 7 degrees of noise-free turn.
  Eigen::Isometry3d truth = Eigen::Isometry3d::Identity();
  truth.linear() =
      (Eigen::AngleAxisd(2.9, Eigen::Vector3d::UnitY()) * Eigen::AngleAxisd(0.3, Eigen::Vector3d::UnitX()) *
       Eigen::AngleAxisd(0.12, Eigen::Vector3d::UnitZ()))
          .toRotationMatrix();
  truth.translation() = Eigen::Vector3d(0.1, -0.05, 1.5);
  std::vector<Eigen::Vector3d> seen_points;
  std::vector<Eigen::Vector3d> seen_normals;
  for (std::size_t i = 0; i < points.size(); ++i) {
    const Eigen::Vector3d p = truth * points[i];
    const Eigen::Vector3d n = truth.linear() * normals[i];
    if (n.dot(p) < -0.2 * p.norm()) {
      seen_points.push_back(p);
      seen_normals.push_back(n);
    }
  }
  const std::vector<FaceDirection> image = face_directions(seen_points, seen_normals, 0.05, 3);
  ASSERT_GE(image.size(), 2U);
  const std::vector<FaceMatch> matches = orientations_from_faces(image, model, 36);
  ASSERT_FALSE(matches.empty());
  // A start 5 cm off: the true pose among those on the planes, up to a slide along the faces' common edge.
  const Eigen::Vector3d start = truth.translation() + Eigen::Vector3d(0.03, -0.02, 0.035);
  const Eigen::Vector3d edge = image[0].normal.cross(image[1].normal).normalized();
  bool found = false;
  for (const FaceMatch& match : matches) {
    if (angle_deg(match.rotation, truth.linear()) > 0.01) {
      continue;
    }
    for (const Eigen::Vector3d& t : positions_on_planes(match, image, model, start)) {
      const Eigen::Vector3d off = t - truth.translation();
      found = found || (off - off.dot(edge) * edge).norm() < 1e-6;
    }
  }
  EXPECT_TRUE(found);
  // No two directions at the model's angles: nothing to match but the turns about the first.
  const std::vector<FaceMatch> one = orientations_from_faces({image[0]}, model, 36);
  EXPECT_EQ(one.size(), 6U * 36U);
}

}  // namespace
}  // namespace rigger::perception::detail
