#include "rigger/sim/pose_math.hpp"

#include <gtest/gtest.h>

#include <cmath>

namespace rigger::sim {
namespace {

TEST(PoseMath, RpyIsYawPitchRollAboutFixedAxes) {
  // R = Rz(yaw) Ry(pitch) Rx(roll): check against an explicit product.
  const Eigen::Vector3d rpy(0.3, -0.7, 1.9);
  const Eigen::Matrix3d expected = (Eigen::AngleAxisd(1.9, Eigen::Vector3d::UnitZ()) *
                                    Eigen::AngleAxisd(-0.7, Eigen::Vector3d::UnitY()) *
                                    Eigen::AngleAxisd(0.3, Eigen::Vector3d::UnitX()))
                                       .toRotationMatrix();
  const Eigen::Isometry3d pose = pose_from_position_rpy(Eigen::Vector3d(1, 2, 3), rpy);
  EXPECT_TRUE(pose.linear().isApprox(expected, 1e-12));
  EXPECT_TRUE(pose.translation().isApprox(Eigen::Vector3d(1, 2, 3)));
  // The camera's rpy (-130, 0, 0): optical z forward must point down and away from the camera.
  const Eigen::Isometry3d camera =
      pose_from_position_rpy(Eigen::Vector3d::Zero(), Eigen::Vector3d(-130.0 * M_PI / 180, 0, 0));
  EXPECT_LT(camera.linear().col(2).z(), 0.0);
  EXPECT_GT(camera.linear().col(2).y(), 0.0);
}

TEST(PoseMath, RotationErrorRoundTrips) {
  const Eigen::Matrix3d actual =
      Eigen::AngleAxisd(0.8, Eigen::Vector3d(1, 2, -1).normalized()).toRotationMatrix();
  const Eigen::Vector3d delta(0.1, -0.4, 0.25);
  const Eigen::Matrix3d desired = rotation_from_vector(delta) * actual;
  EXPECT_TRUE(rotation_error(desired, actual).isApprox(delta, 1e-12));
  EXPECT_TRUE(rotation_error(actual, actual).isZero(1e-12));
  EXPECT_TRUE(rotation_from_vector(Eigen::Vector3d::Zero()).isIdentity());
  // Half a turn: angle pi, either axis sign.
  const Eigen::Vector3d half_turn =
      rotation_vector(Eigen::AngleAxisd(M_PI, Eigen::Vector3d::UnitY()).toRotationMatrix());
  EXPECT_NEAR(half_turn.norm(), M_PI, 1e-9);
  EXPECT_NEAR(std::abs(half_turn.y()), M_PI, 1e-9);
}

TEST(PoseMath, PoseErrorStacksPositionAndRotation) {
  Eigen::Isometry3d actual = Eigen::Isometry3d::Identity();
  Eigen::Isometry3d desired = Eigen::Isometry3d::Identity();
  desired.translation() = Eigen::Vector3d(0.1, 0, -0.2);
  desired.linear() = Eigen::AngleAxisd(0.2, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  const Eigen::Matrix<double, 6, 1> error = pose_error(desired, actual);
  EXPECT_TRUE(error.head<3>().isApprox(Eigen::Vector3d(0.1, 0, -0.2)));
  EXPECT_TRUE(error.tail<3>().isApprox(Eigen::Vector3d(0, 0, 0.2)));
}

}  // namespace
}  // namespace rigger::sim
