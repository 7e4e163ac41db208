#include "rigger/sim/pixel_noise.hpp"

#include <algorithm>
#include <type_traits>

namespace rigger::sim {

void PixelNoise::add(cv::Mat& image) {
  if (!(stddev_ > 0.0)) {
    return;
  }
  constexpr std::size_t kBankFrames = 4;
  const std::size_t pixels = image.total();
  if (bank_.total() < kBankFrames * pixels) {
    bank_.create(1, static_cast<int>(kBankFrames * pixels), CV_32FC1);
    rng_.fill(bank_, cv::RNG::NORMAL, 0.0, stddev_);
  }
  const std::size_t bank = bank_.total();
  const auto offset = static_cast<std::size_t>(rng_.uniform(0, static_cast<int>(bank)));
  const float* noise = bank_.ptr<float>();
  const std::size_t first = std::min(pixels, bank - offset);
  const auto apply = [&](auto* out) {
    for (std::size_t i = 0; i < first; ++i) {
      out[i] = cv::saturate_cast<std::remove_reference_t<decltype(out[i])>>(out[i] + noise[offset + i]);
    }
    for (std::size_t i = first; i < pixels; ++i) {
      out[i] = cv::saturate_cast<std::remove_reference_t<decltype(out[i])>>(out[i] + noise[i - first]);
    }
  };
  if (image.type() == CV_32FC1) {
    apply(image.ptr<float>());
  } else if (image.type() == CV_8UC1) {
    apply(image.ptr<uchar>());
  }
}

}  // namespace rigger::sim
