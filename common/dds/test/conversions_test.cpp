#include "rigger/dds/conversions.hpp"

#include <gtest/gtest.h>

#include <type_traits>
#include <utility>

namespace rigger::dds {
namespace {

TEST(Conversions, TimeRoundTripIncludingNegativeAndNanoseconds) {
  for (std::int64_t ns : {std::int64_t{0}, std::int64_t{1'700'000'000'999'999'999}, std::int64_t{-1}, std::int64_t{-1'500'000'000}}) {
    const auto wire = to_wire(from_unix_ns(ns));
    EXPECT_LT(wire.nanosec, 1'000'000'000u);
    EXPECT_EQ(to_unix_ns(to_domain(wire)), ns);
  }
  const auto neg = to_wire(from_unix_ns(-1));
  EXPECT_EQ(neg.sec, -1);
  EXPECT_EQ(neg.nanosec, 999'999'999u);
}

TEST(Conversions, PoseRoundTrip) {
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  pose.translate(Eigen::Vector3d(3.55, 1.75, 1.2));
  pose.rotate(Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 2, 3).normalized()));
  const Eigen::Isometry3d back = to_domain(to_wire(pose));
  EXPECT_TRUE(back.isApprox(pose, 1e-12));
}

TEST(Conversions, QuaternionFieldOrderIsXyzw) {
  const auto q = to_wire(Eigen::Quaterniond(0.5, 0.1, 0.2, 0.3));
  EXPECT_DOUBLE_EQ(q.x, 0.1);
  EXPECT_DOUBLE_EQ(q.w, 0.5);
  EXPECT_DOUBLE_EQ(to_domain(q).w(), 0.5);
}

TEST(Conversions, ZeroQuaternionBecomesIdentityRotation) {
  rigger_geometry_Pose p{};
  p.position = {1, 2, 3};
  const auto pose = to_domain(p);
  EXPECT_TRUE(pose.linear().isApprox(Eigen::Matrix3d::Identity()));
  EXPECT_EQ(pose.translation(), Eigen::Vector3d(1, 2, 3));
}

TEST(Conversions, TwistWrenchAndCovarianceRoundTrip) {
  Vector6d v;
  v << 1, 2, 3, 4, 5, 6;
  EXPECT_EQ(to_domain(to_wire_twist(v)), v);
  EXPECT_EQ(to_domain(to_wire_wrench(v)), v);
  EXPECT_EQ(to_wire_twist(v).angular.x, 4);
  Eigen::Matrix<double, 6, 6> cov;
  for (int i = 0; i < 36; ++i) cov(i / 6, i % 6) = i;
  double wire[36];
  covariance_to_wire(cov, wire);
  EXPECT_EQ(wire[7], 7);  // row-major: (1, 1)
  EXPECT_EQ(wire[1], 1);  // (0, 1)
  EXPECT_EQ(covariance_to_domain(wire), cov);
}

TEST(Conversions, StringsAndSequences) {
  EXPECT_EQ(to_string(nullptr), "");
  std::vector<std::string> names{"a", "bb"};
  std::vector<char*> storage;
  rigger_system_PeerView view{};
  wire_string_sequence(view.alive_peers, names, storage);
  EXPECT_EQ(to_string_vector(view.alive_peers), names);
  EXPECT_FALSE(view.alive_peers._release);
  std::vector<double> values{1.5, 2.5};
  rigger_sensing_JointState js{};
  wire_sequence(js.position, values);
  EXPECT_EQ(to_vector<double>(js.position), values);
}

}  // namespace
}  // namespace rigger::dds

namespace rigger::dds {
namespace {

template <typename Arg, typename = void>
struct CanBorrow : std::false_type {};
template <typename Arg>
struct CanBorrow<Arg, std::void_t<decltype(wire_string(std::declval<Arg>()))>> : std::true_type {};

// wire_string() returns a pointer into its argument: a temporary would dangle before the write.
static_assert(CanBorrow<const std::string&>::value, "a named string can be borrowed");
static_assert(CanBorrow<const char (&)[1]>::value, "a literal lives forever");
static_assert(!CanBorrow<std::string>::value, "a temporary std::string must not be borrowed");
static_assert(!CanBorrow<const char*>::value, "a pointer would be copied into a temporary std::string");

TEST(Conversions, WireStringBorrowsLiteralAndNamedString) {
  const std::string named = "abc";
  EXPECT_EQ(wire_string(named), named.c_str());
  const char* empty = wire_string("");
  EXPECT_STREQ(empty, "");
}

}  // namespace
}  // namespace rigger::dds
