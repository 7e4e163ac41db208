#include "rigger/sim/crane_drive.hpp"

#include <algorithm>
#include <cmath>

namespace rigger::sim {

TravelDrive::TravelDrive(const Params& params) : params_(params) {}

void TravelDrive::reset(double position_m) {
  reference_m_ = std::clamp(position_m, params_.position_min_m, params_.position_max_m);
  setpoint_mps_ = 0.0;
  ramped_mps_ = 0.0;
}

double TravelDrive::update(double position_m, double velocity_mps, double dt_s) {
  if (dt_s <= 0.0) {
    return 0.0;
  }
  const double max_change = params_.max_accel_mps2 * dt_s;
  const double previous_ramped = ramped_mps_;
  ramped_mps_ += std::clamp(setpoint_mps_ - ramped_mps_, -max_change, max_change);

  // Integrate the ramped setpoint into the reference; at an end stop, or when the axis is held
  // back (following error), the reference waits instead of winding up.
  const double previous_reference = reference_m_;
  const double low = std::max(params_.position_min_m, position_m - params_.max_following_error_m);
  const double high = std::min(params_.position_max_m, position_m + params_.max_following_error_m);
  reference_m_ =
      std::clamp(reference_m_ + ramped_mps_ * dt_s, std::min(low, high), std::max(low, high));
  const bool held = std::abs(reference_m_ - (previous_reference + ramped_mps_ * dt_s)) > 1e-12;
  const double feedforward_mps = held ? 0.0 : ramped_mps_;
  const double feedforward_accel = held ? 0.0 : (ramped_mps_ - previous_ramped) / dt_s;
  if (held) {
    ramped_mps_ = (reference_m_ - previous_reference) / dt_s;
  }

  const double velocity_reference =
      feedforward_mps + params_.position_gain_per_s * (reference_m_ - position_m);
  return feedforward_accel + (velocity_reference - velocity_mps) / params_.velocity_time_constant_s;
}

HoistDrum::HoistDrum(const Params& params) : params_(params) {}

void HoistDrum::reset(double payout_m) {
  payout_m_ = std::clamp(payout_m, params_.payout_min_m, params_.payout_max_m);
  rate_mps_ = 0.0;
  setpoint_mps_ = 0.0;
}

void HoistDrum::update(double dt_s) {
  if (dt_s <= 0.0) {
    return;
  }
  const double wanted_accel = (setpoint_mps_ - rate_mps_) / params_.velocity_time_constant_s;
  const double accel = std::clamp(wanted_accel, -params_.max_accel_mps2, params_.max_accel_mps2);
  // Do not overshoot the setpoint within one step.
  const double step = accel * dt_s;
  if (std::abs(step) >= std::abs(setpoint_mps_ - rate_mps_)) {
    rate_mps_ = setpoint_mps_;
  } else {
    rate_mps_ += step;
  }
  payout_m_ += rate_mps_ * dt_s;
  if (payout_m_ <= params_.payout_min_m) {
    payout_m_ = params_.payout_min_m;
    rate_mps_ = std::max(0.0, rate_mps_);
  } else if (payout_m_ >= params_.payout_max_m) {
    payout_m_ = params_.payout_max_m;
    rate_mps_ = std::min(0.0, rate_mps_);
  }
}

double rope_tension_n(double hook_distance_m, double hook_speed_mps, double payout_m,
                      double payout_rate_mps, const RopeParams& params) {
  const double stretch = hook_distance_m - payout_m;
  if (stretch <= 0.0) {
    return 0.0;
  }
  return std::max(0.0, params.stiffness_n_per_m * stretch +
                           params.damping_n_s_per_m * (hook_speed_mps - payout_rate_mps));
}

}  // namespace rigger::sim
