#include "boundary.hpp"

#include <cmath>
#include <functional>
#include <limits>

#include <gtest/gtest.h>

namespace rigger::ros2_bridge {
namespace {

using namespace std::chrono_literals;

const WallTime kNow = from_unix_ns(1'700'000'000'000'000'000);

TEST(AgeCheck, FreshUpToTheMaximumAgeAndSkew) {
  const AgeLimits limits{100ms, 20ms};
  EXPECT_EQ(check_age(kNow, kNow, limits), AgeVerdict::kFresh);
  EXPECT_EQ(check_age(kNow - 100ms, kNow, limits), AgeVerdict::kFresh);
  EXPECT_EQ(check_age(kNow - 101ms, kNow, limits), AgeVerdict::kStale);
  EXPECT_EQ(check_age(kNow + 20ms, kNow, limits), AgeVerdict::kFresh);
  EXPECT_EQ(check_age(kNow + 21ms, kNow, limits), AgeVerdict::kFromTheFuture);
}

TEST(AgeCheck, AZeroStampIsUnstampedNotAncient) {
  EXPECT_EQ(check_age(WallTime{}, kNow, AgeLimits{}), AgeVerdict::kUnstamped);
  EXPECT_EQ(age_verdict_name(AgeVerdict::kUnstamped), "unstamped");
  EXPECT_EQ(age_verdict_name(AgeVerdict::kStale), "stale");
}

Vector6d twist(double vx, double vy, double vz, double wx, double wy, double wz) {
  Vector6d t;
  t << vx, vy, vz, wx, wy, wz;
  return t;
}

TEST(TwistLimit, WithinLimitsPassesUnchanged) {
  const TwistLimits limits{0.25, 0.5, OverLimit::kClamp};
  const auto r = limit_twist(twist(0.1, -0.2, 0.0, 0.0, 0.3, -0.4), limits);  // norms 0.224, 0.5
  EXPECT_EQ(r.verdict, TwistVerdict::kWithin);
  EXPECT_TRUE(r.send());
  EXPECT_EQ(r.twist, twist(0.1, -0.2, 0.0, 0.0, 0.3, -0.4));
}

TEST(TwistLimit, ClampScalesEachPartToItsLimitKeepingDirection) {
  const TwistLimits limits{0.25, 0.5, OverLimit::kClamp};
  const auto r = limit_twist(twist(0.3, 0.4, 0.0, 0.0, 0.0, 0.1), limits);  // linear 0.5 > 0.25
  ASSERT_EQ(r.verdict, TwistVerdict::kClamped);
  EXPECT_TRUE(r.send());
  EXPECT_NEAR(r.twist.head<3>().norm(), 0.25, 1e-12);
  EXPECT_NEAR(r.twist(0), 0.15, 1e-12);
  EXPECT_NEAR(r.twist(1), 0.2, 1e-12);
  EXPECT_EQ(r.twist(5), 0.1);  // the angular part was within its limit: untouched

  const auto a = limit_twist(twist(0, 0, 0.1, 0, -2.0, 0), limits);
  ASSERT_EQ(a.verdict, TwistVerdict::kClamped);
  EXPECT_EQ(a.twist(2), 0.1);
  EXPECT_NEAR(a.twist(4), -0.5, 1e-12);
}

TEST(TwistLimit, RefuseDropsAnythingAboveALimit) {
  const TwistLimits limits{0.25, 0.5, OverLimit::kRefuse};
  const auto r = limit_twist(twist(0, 0, 0, 0, 0, 0.51), limits);
  EXPECT_EQ(r.verdict, TwistVerdict::kOverLimit);
  EXPECT_FALSE(r.send());
  EXPECT_EQ(r.twist, Vector6d::Zero());
  EXPECT_EQ(limit_twist(twist(0.25, 0, 0, 0, 0, 0.5), limits).verdict, TwistVerdict::kWithin);
}

TEST(TwistLimit, NotFiniteIsAlwaysRefused) {
  const TwistLimits clamp{0.25, 0.5, OverLimit::kClamp};
  EXPECT_EQ(limit_twist(twist(std::nan(""), 0, 0, 0, 0, 0), clamp).verdict, TwistVerdict::kNotFinite);
  const auto r = limit_twist(twist(0, 0, 0, std::numeric_limits<double>::infinity(), 0, 0), clamp);
  EXPECT_EQ(r.verdict, TwistVerdict::kNotFinite);
  EXPECT_FALSE(r.send());
}

TEST(RefusalCounter, LogsTheFirstThenAtMostOncePerInterval) {
  RefusalCounter c(1s);
  const SteadyTime t0{};
  EXPECT_TRUE(c.count(t0));
  EXPECT_EQ(c.batch(), 1u);
  EXPECT_FALSE(c.count(t0 + 100ms));
  EXPECT_FALSE(c.count(t0 + 999ms));
  EXPECT_TRUE(c.count(t0 + 1000ms));
  EXPECT_EQ(c.batch(), 3u);  // the two silent ones and this one
  EXPECT_EQ(c.total(), 4u);
  EXPECT_FALSE(c.count(t0 + 1500ms));
  EXPECT_TRUE(c.count(t0 + 2500ms));
  EXPECT_EQ(c.batch(), 2u);
  EXPECT_EQ(c.total(), 6u);
}

}  // namespace
}  // namespace rigger::ros2_bridge

namespace rigger::ros2_bridge {
namespace {

// mono8 crosses as it is, its row padding dropped; colour becomes BT.601 grey whichever the channel order.
TEST(ToMono8, GreyPassesColourBecomesLumaRowsComeOutTight) {
  std::vector<std::uint8_t> out;
  // 3 × 2 mono8 with a step of 4 (one padding byte per row).
  const std::vector<std::uint8_t> mono = {1, 2, 3, 99, 4, 5, 6, 99};
  ASSERT_EQ(to_mono8("mono8", 3, 2, 4, mono.data(), mono.size(), out), ImageVerdict::kOk);
  EXPECT_EQ(out, (std::vector<std::uint8_t>{1, 2, 3, 4, 5, 6}));
  // Pure red, green, blue and white, as rgb8 and as bgra8.
  const std::vector<std::uint8_t> rgb = {255, 0, 0, 0, 255, 0, 0, 0, 255, 255, 255, 255};
  ASSERT_EQ(to_mono8("rgb8", 4, 1, 12, rgb.data(), rgb.size(), out), ImageVerdict::kOk);
  EXPECT_EQ(out, (std::vector<std::uint8_t>{76, 150, 29, 255}));
  const std::vector<std::uint8_t> bgra = {0, 0, 255, 7, 0, 255, 0, 7, 255, 0, 0, 7, 255, 255, 255, 7};
  ASSERT_EQ(to_mono8("bgra8", 4, 1, 16, bgra.data(), bgra.size(), out), ImageVerdict::kOk);
  EXPECT_EQ(out, (std::vector<std::uint8_t>{76, 150, 29, 255}));
}

TEST(ToMono8, WhatCannotBeReadIsRefusedAndLeavesTheOutputAlone) {
  std::vector<std::uint8_t> out = {42};
  const std::vector<std::uint8_t> data(12, 0);
  EXPECT_EQ(to_mono8("16UC1", 2, 2, 4, data.data(), 8, out), ImageVerdict::kEncoding);
  EXPECT_EQ(to_mono8("bayer_rggb8", 2, 2, 2, data.data(), 4, out), ImageVerdict::kEncoding);
  EXPECT_EQ(to_mono8("mono8", 0, 2, 2, data.data(), 0, out), ImageVerdict::kSize);
  EXPECT_EQ(to_mono8("mono8", kMaxImageSide + 1, 1, kMaxImageSide + 1, data.data(), 12, out), ImageVerdict::kSize);
  EXPECT_EQ(to_mono8("rgb8", 2, 2, 5, data.data(), 10, out), ImageVerdict::kLayout);   // step < 2 × 3
  EXPECT_EQ(to_mono8("mono8", 2, 2, 2, data.data(), 3, out), ImageVerdict::kLayout);   // 3 bytes, not 4
  EXPECT_EQ(to_mono8("mono8", 2, 2, 2, data.data(), 12, out), ImageVerdict::kLayout);  // 12, not 4
  EXPECT_EQ(out, std::vector<std::uint8_t>{42});
  EXPECT_EQ(image_verdict_name(ImageVerdict::kLayout), "layout");
}

}  // namespace
TEST(CheckCameraInfo, TakesAFullPlumbBobCameraAndSaysWhyItRefusesAnyOther) {
  const double d[5] = {-0.2, 0.05, 0.001, -0.001, 0.0};
  const double k[9] = {1000, 0, 639.5, 0, 1000, 359.5, 0, 0, 1};
  const double nan_k[9] = {std::nan(""), 0, 639.5, 0, 1000, 359.5, 0, 0, 1};
  const double zero_f[9] = {0, 0, 639.5, 0, 1000, 359.5, 0, 0, 1};
  const double p[12] = {1000, 0, 639.5, 0, 0, 1000, 359.5, 0, 0, 0, 1, 0};
  const CameraInfoFields good{"plumb_bob", d, 5, k, p, 1280, 720};
  // The verdict on the good camera changed by `change`.
  const auto verdict = [&](const std::function<void(CameraInfoFields&)>& change) {
    CameraInfoFields info = good;
    change(info);
    return check_camera_info(info);
  };
  EXPECT_EQ(verdict([](CameraInfoFields&) {}), CameraInfoVerdict::kOk);
  EXPECT_EQ(verdict([](CameraInfoFields& i) { i.d_count = 4; }), CameraInfoVerdict::kOk);  // k3 left out
  // An undistorted camera that names no model, with the full image as its region.
  EXPECT_EQ(verdict([](CameraInfoFields& i) {
              i.distortion_model = "";
              i.d_count = 0;
              i.roi_width = 1280;
              i.roi_height = 720;
            }),
            CameraInfoVerdict::kOk);
  EXPECT_EQ(verdict([](CameraInfoFields& i) { i.distortion_model = "rational_polynomial"; }),
            CameraInfoVerdict::kModel);
  EXPECT_EQ(verdict([](CameraInfoFields& i) { i.d_count = 3; }), CameraInfoVerdict::kCoefficients);
  EXPECT_EQ(verdict([](CameraInfoFields& i) { i.width = 0; }), CameraInfoVerdict::kSize);
  EXPECT_EQ(verdict([&](CameraInfoFields& i) { i.k = nan_k; }), CameraInfoVerdict::kNotFinite);
  EXPECT_EQ(verdict([&](CameraInfoFields& i) { i.k = zero_f; }), CameraInfoVerdict::kNotFinite);
  EXPECT_EQ(verdict([](CameraInfoFields& i) { i.binning_x = 2; }), CameraInfoVerdict::kCropped);
  EXPECT_EQ(verdict([](CameraInfoFields& i) {
              i.roi_x = 10;
              i.roi_width = 640;
              i.roi_height = 360;
            }),
            CameraInfoVerdict::kCropped);
  EXPECT_EQ(camera_info_verdict_name(CameraInfoVerdict::kCropped), "binned_or_cropped");
}

}  // namespace rigger::ros2_bridge
