#pragma once
/// @file
/// What a structured-light depth sensor does to a perfect depth image: noise that grows with the square
/// of the distance, holes where the surface is seen at a grazing angle, and holes along depth edges
/// (the projector's pattern is shadowed or smeared there). Applied to the simulated camera's depth
/// image after rendering; the grey image is not touched.

#include <opencv2/core.hpp>

#include <cstdint>

#include "rigger/sim/camera_scene.hpp"

namespace rigger::sim {

struct DepthNoiseSettings {
  /// Standard deviation of the depth noise at 1 m, metres; at distance z it is this times z² (0: none).
  double stddev_at_1m_m = 0.0;
  /// Pixels whose surface normal is more than this from the viewing ray become NaN (0: none). Degrees.
  double grazing_deg = 0.0;
  /// Pixels with a 4-neighbour more than this nearer or farther become NaN, on both sides (0: none). Metres.
  double edge_gap_m = 0.0;

  bool any() const { return stddev_at_1m_m > 0.0 || grazing_deg > 0.0 || edge_gap_m > 0.0; }
};

/// Degrades depth images in place. Deterministic for a seed and call sequence. Not thread safe.
class DepthNoise {
 public:
  /// @throws std::invalid_argument for a negative setting or grazing_deg >= 90.
  DepthNoise(const CameraModel& camera, DepthNoiseSettings settings, std::uint64_t seed);

  /// `depth_m`: CV_32FC1 of the camera's size, metres along the optical axis, NaN where nothing was
  /// seen (MujocoCamera's depth). Holes first (from the perfect depth), then the noise. Another type
  /// or size is left alone.
  void apply(cv::Mat& depth_m);
  const DepthNoiseSettings& settings() const { return settings_; }

 private:
  CameraModel camera_;
  DepthNoiseSettings settings_;
  cv::RNG rng_;
  cv::Mat holes_;  // CV_8UC1 scratch
};

}  // namespace rigger::sim
