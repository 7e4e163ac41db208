#include "boundary.hpp"

#include <algorithm>
#include <cmath>

namespace rigger::ros2_bridge {

std::string_view age_verdict_name(AgeVerdict verdict) {
  switch (verdict) {
    case AgeVerdict::kFresh:
      return "fresh";
    case AgeVerdict::kStale:
      return "stale";
    case AgeVerdict::kFromTheFuture:
      return "from_the_future";
    case AgeVerdict::kUnstamped:
      return "unstamped";
  }
  return "unknown";
}

AgeVerdict check_age(WallTime stamp, WallTime now, const AgeLimits& limits) {
  if (stamp.time_since_epoch().count() == 0) return AgeVerdict::kUnstamped;
  if (stamp > now + limits.max_future_skew) return AgeVerdict::kFromTheFuture;
  if (now - stamp > limits.max_age) return AgeVerdict::kStale;
  return AgeVerdict::kFresh;
}

std::string_view twist_verdict_name(TwistVerdict verdict) {
  switch (verdict) {
    case TwistVerdict::kWithin:
      return "within";
    case TwistVerdict::kClamped:
      return "clamped";
    case TwistVerdict::kOverLimit:
      return "over_limit";
    case TwistVerdict::kNotFinite:
      return "not_finite";
  }
  return "unknown";
}

bool all_finite(const Vector6d& v) {
  return v.allFinite();
}

LimitedTwist limit_twist(const Vector6d& twist, const TwistLimits& limits) {
  if (!all_finite(twist)) return {TwistVerdict::kNotFinite, Vector6d::Zero()};
  const double linear = twist.head<3>().norm();
  const double angular = twist.tail<3>().norm();
  if (linear <= limits.max_linear_mps && angular <= limits.max_angular_radps) return {TwistVerdict::kWithin, twist};
  if (limits.over_limit == OverLimit::kRefuse) return {TwistVerdict::kOverLimit, Vector6d::Zero()};
  Vector6d out = twist;
  if (linear > limits.max_linear_mps) out.head<3>() *= limits.max_linear_mps / linear;
  if (angular > limits.max_angular_radps) out.tail<3>() *= limits.max_angular_radps / angular;
  return {TwistVerdict::kClamped, out};
}

std::string_view image_verdict_name(ImageVerdict verdict) {
  switch (verdict) {
    case ImageVerdict::kOk: return "ok";
    case ImageVerdict::kEncoding: return "encoding";
    case ImageVerdict::kSize: return "size";
    case ImageVerdict::kLayout: return "layout";
  }
  return "unknown";
}

std::string_view camera_info_verdict_name(CameraInfoVerdict verdict) {
  switch (verdict) {
    case CameraInfoVerdict::kOk: return "ok";
    case CameraInfoVerdict::kModel: return "distortion_model";
    case CameraInfoVerdict::kCoefficients: return "coefficients";
    case CameraInfoVerdict::kSize: return "size";
    case CameraInfoVerdict::kNotFinite: return "not_finite";
    case CameraInfoVerdict::kCropped: return "binned_or_cropped";
  }
  return "unknown";
}

CameraInfoVerdict check_camera_info(const CameraInfoFields& info) {
  const bool undistorted = info.distortion_model.empty() && info.d_count == 0;
  if (info.distortion_model != "plumb_bob" && !undistorted) return CameraInfoVerdict::kModel;
  if (info.d_count != 0 && info.d_count != 4 && info.d_count != 5) return CameraInfoVerdict::kCoefficients;
  if (info.width == 0 || info.height == 0 || info.width > kMaxImageSide || info.height > kMaxImageSide) {
    return CameraInfoVerdict::kSize;
  }
  const auto finite = [](const double* v, std::size_t n) {
    for (std::size_t i = 0; i < n; ++i) {
      if (!std::isfinite(v[i])) return false;
    }
    return true;
  };
  if (!finite(info.d, info.d_count) || !finite(info.k, 9) || !finite(info.p, 12) || !(info.k[0] > 0.0) ||
      !(info.k[4] > 0.0)) {
    return CameraInfoVerdict::kNotFinite;
  }
  const bool binned = info.binning_x > 1 || info.binning_y > 1;
  const bool full_roi = info.roi_width == 0 || info.roi_height == 0 ||
                        (info.roi_x == 0 && info.roi_y == 0 && info.roi_width == info.width &&
                         info.roi_height == info.height);
  if (binned || !full_roi) return CameraInfoVerdict::kCropped;
  return CameraInfoVerdict::kOk;
}

ImageVerdict to_mono8(std::string_view encoding, std::uint32_t width, std::uint32_t height, std::uint32_t step,
                      const std::uint8_t* data, std::size_t size, std::vector<std::uint8_t>& out) {
  // Bytes per pixel and where red and blue are (green is always 1).
  int channels = 0, red = 0, blue = 0;
  if (encoding == "mono8") {
    channels = 1;
  } else if (encoding == "rgb8" || encoding == "rgba8") {
    channels = encoding == "rgb8" ? 3 : 4;
    blue = 2;
  } else if (encoding == "bgr8" || encoding == "bgra8") {
    channels = encoding == "bgr8" ? 3 : 4;
    red = 2;
  } else {
    return ImageVerdict::kEncoding;
  }
  if (width == 0 || height == 0 || width > kMaxImageSide || height > kMaxImageSide) return ImageVerdict::kSize;
  const std::size_t row_bytes = std::size_t{width} * static_cast<std::size_t>(channels);
  if (step < row_bytes || size != std::size_t{step} * height || (size > 0 && data == nullptr)) return ImageVerdict::kLayout;
  out.resize(std::size_t{width} * height);
  for (std::uint32_t y = 0; y < height; ++y) {
    const std::uint8_t* row = data + std::size_t{y} * step;
    std::uint8_t* grey = out.data() + std::size_t{y} * width;
    if (channels == 1) {
      std::copy(row, row + width, grey);
      continue;
    }
    for (std::uint32_t x = 0; x < width; ++x) {
      const std::uint8_t* p = row + std::size_t{x} * static_cast<std::size_t>(channels);
      // Integer BT.601 luma: (299 R + 587 G + 114 B + 500) / 1000.
      grey[x] = static_cast<std::uint8_t>((299u * p[red] + 587u * p[1] + 114u * p[blue] + 500u) / 1000u);
    }
  }
  return ImageVerdict::kOk;
}

bool RefusalCounter::count(SteadyTime now) {
  ++total_;
  ++pending_;
  if (logged_ && now - last_log_ < interval_) return false;
  logged_ = true;
  last_log_ = now;
  batch_ = pending_;
  pending_ = 0;
  return true;
}

}  // namespace rigger::ros2_bridge
