#pragma once
/// @file
/// What the ROS 2 bridge lets through its boundary (rigger's safety rules applied to ROS 2 drivers): samples no
/// older than a configured age, twist commands within the cell's speed limits, and how often a refusal
/// may be logged. Pure: no DDS, no wire types, time is passed in. Not thread-safe.

#include <chrono>
#include <cstdint>
#include <string_view>
#include <vector>

#include <Eigen/Core>

#include "rigger/base/time.hpp"

namespace rigger::ros2_bridge {

using Vector6d = Eigen::Matrix<double, 6, 1>;  ///< (linear x y z, angular x y z) or (force; torque)

/// Whether a sample's stamp is fresh enough to cross the bridge.
enum class AgeVerdict {
  kFresh,
  kStale,          ///< older than the maximum age
  kFromTheFuture,  ///< stamped further ahead of our clock than the allowed skew
  kUnstamped,      ///< stamp 0: the sender did not stamp it, so its age is unknown
};
/// "fresh", "stale", "from_the_future", "unstamped".
std::string_view age_verdict_name(AgeVerdict verdict);

/// Age limits of one bridged stream. Stamps are wall clock (ROS 2 drivers stamp with the system clock
/// unless use_sim_time is set; rigger stamps with the wall clock).
struct AgeLimits {
  std::chrono::nanoseconds max_age{std::chrono::milliseconds(100)};
  std::chrono::nanoseconds max_future_skew{std::chrono::milliseconds(50)};
};

/// The verdict on a sample stamped `stamp` and received at `now`.
AgeVerdict check_age(WallTime stamp, WallTime now, const AgeLimits& limits);

/// What to do with a twist above the limits.
enum class OverLimit {
  kClamp,   ///< scale the linear (angular) part down to the limit, keeping its direction
  kRefuse,  ///< drop the command (MoveIt Servo then stops on its own command timeout)
};

/// Speed limits of twist commands leaving rigger for a ROS 2 driver.
struct TwistLimits {
  double max_linear_mps = 0.25;    ///< on the norm of the linear part
  double max_angular_radps = 0.5;  ///< on the norm of the angular part
  OverLimit over_limit = OverLimit::kClamp;
};

enum class TwistVerdict {
  kWithin,
  kClamped,    ///< above a limit, scaled down (OverLimit::kClamp)
  kOverLimit,  ///< above a limit, refused (OverLimit::kRefuse)
  kNotFinite,  ///< NaN or infinite: always refused
};
/// "within", "clamped", "over_limit", "not_finite".
std::string_view twist_verdict_name(TwistVerdict verdict);

struct LimitedTwist {
  TwistVerdict verdict = TwistVerdict::kWithin;
  Vector6d twist = Vector6d::Zero();  ///< what to send: the input, clamped, or zero when refused
  /// Whether `twist` may be sent.
  bool send() const { return verdict == TwistVerdict::kWithin || verdict == TwistVerdict::kClamped; }
};

/// Applies `limits` to `twist` (m/s, rad/s). A clamp scales the linear and the angular part separately
/// by their norms, so the direction of each is kept.
LimitedTwist limit_twist(const Vector6d& twist, const TwistLimits& limits);

/// Whether a wrench (or any 6-vector) holds only finite numbers.
bool all_finite(const Vector6d& v);

/// Why a camera image cannot cross (kOk when it can).
enum class ImageVerdict {
  kOk,
  kEncoding,  ///< not one of mono8, rgb8, bgr8, rgba8, bgra8
  kSize,      ///< width or height 0 or above kMaxImageSide
  kLayout,    ///< step below width × bytes per pixel, or data other than step × height bytes
};
/// "ok", "encoding", "size", "layout".
std::string_view image_verdict_name(ImageVerdict verdict);
inline constexpr std::uint32_t kMaxImageSide = 16384;

/// A ROS 2 camera image (sensor_msgs/Image fields) as rigger's tracker takes it: 8-bit grey, rows tight
/// (step = width). mono8 crosses as it is; rgb8, bgr8, rgba8 and bgra8 become grey with the BT.601 luma
/// weights (0.299 R + 0.587 G + 0.114 B, rounded); anything else is refused. `out` is resized to
/// width × height on kOk and left alone otherwise.
ImageVerdict to_mono8(std::string_view encoding, std::uint32_t width, std::uint32_t height, std::uint32_t step,
                      const std::uint8_t* data, std::size_t size, std::vector<std::uint8_t>& out);

/// What a camera driver's sensor_msgs/CameraInfo must be for rigger to take it as rigger/camera/info.
enum class CameraInfoVerdict {
  kOk,
  kModel,         ///< distortion_model is not plumb_bob (the one model rigger's camera model has)
  kCoefficients,  ///< plumb_bob with other than 0, 4 or 5 coefficients (k1 k2 p1 p2 [k3])
  kSize,          ///< width or height 0 or above kMaxImageSide
  kNotFinite,     ///< a coefficient or matrix entry is NaN or infinite, or the focal lengths are not positive
  kCropped,       ///< binned, or a region of interest other than the full image: rigger's images are full
};
std::string_view camera_info_verdict_name(CameraInfoVerdict verdict);

/// The fields of a sensor_msgs/CameraInfo the check reads.
struct CameraInfoFields {
  std::string_view distortion_model;
  const double* d = nullptr;
  std::size_t d_count = 0;
  const double* k = nullptr;  ///< 9, row-major
  const double* p = nullptr;  ///< 12, row-major
  std::uint32_t width = 0;
  std::uint32_t height = 0;
  std::uint32_t binning_x = 0;
  std::uint32_t binning_y = 0;
  std::uint32_t roi_x = 0, roi_y = 0, roi_width = 0, roi_height = 0;
};
/// Whether rigger can take these intrinsics: plumb_bob (an empty model with no coefficients counts as an
/// undistorted plumb_bob), finite, positive focal lengths, unbinned, the full image.
CameraInfoVerdict check_camera_info(const CameraInfoFields& info);

/// Counts refusals and says when one may be logged: at most once per `interval`, reporting how many
/// were refused since the last log line.
class RefusalCounter {
 public:
  explicit RefusalCounter(std::chrono::nanoseconds interval) : interval_(interval) {}
  /// Counts one refusal at `now`; returns true when it should be logged now.
  bool count(SteadyTime now);
  /// Refusals since the bridge started.
  std::uint64_t total() const { return total_; }
  /// When count() returned true: the refusals since the previous log line, this one included.
  std::uint64_t batch() const { return batch_; }

 private:
  std::chrono::nanoseconds interval_;
  std::uint64_t total_ = 0;
  std::uint64_t pending_ = 0;
  std::uint64_t batch_ = 0;
  bool logged_ = false;
  SteadyTime last_log_{};
};

}  // namespace rigger::ros2_bridge
