#pragma once
/// @file
/// The simulated camera's pixel noise, shared by its renderers.

#include <opencv2/core.hpp>

#include <cstdint>

namespace rigger::sim {

/// Gaussian pixel noise. Drawing a million Gaussian samples per frame costs more than the rest of
/// a frame, so frames take a window at a random offset into a bank a few frames long, drawn at the
/// first frame: independent noise within a frame, a different draw in every frame. Deterministic
/// for a seed and call sequence. Not thread safe.
class PixelNoise {
 public:
  /// stddev in the image's units (grey levels); 0 adds nothing.
  PixelNoise(double stddev, std::uint64_t seed) : stddev_(stddev), rng_(seed) {}
  /// Adds noise to a continuous image: CV_32FC1 in place, CV_8UC1 rounded and saturated; other
  /// types are left alone.
  void add(cv::Mat& image);
  double stddev() const { return stddev_; }

 private:
  double stddev_;
  cv::RNG rng_;
  cv::Mat bank_;  // CV_32FC1, 1 x (several frames)
};

}  // namespace rigger::sim
