#pragma once
/// @file
/// Range checks shared by the laws' find_problem() functions: each returns the first problem as a
/// ConfigProblem (pointer relative to the checked object, expectation in words with the unit).

#include <optional>
#include <string>

#include <Eigen/Core>

#include "control_types.hpp"

namespace rigger::control {

/// What a checked number must be.
enum class Bound { kNonNegative, kPositive };

/// Every element finite and within `bound`; the pointer of element i is pointer + "/" + i, and the
/// message names the axis (x, y, z for 3 elements; x, y, z, rx, ry, rz for 6).
std::optional<ConfigProblem> check_axes(const Eigen::Ref<const Eigen::VectorXd>& values, const std::string& pointer,
                                        Bound bound, const char* unit);
/// `value` finite and within `bound`.
std::optional<ConfigProblem> check_scalar(double value, const std::string& pointer, Bound bound, const char* unit);
/// Every element finite.
std::optional<ConfigProblem> check_finite(const Eigen::Ref<const Eigen::VectorXd>& values, const std::string& pointer,
                                          const char* unit);
/// `problem` with `prefix` put before its pointer.
std::optional<ConfigProblem> prefixed(std::optional<ConfigProblem> problem, const std::string& prefix);

}  // namespace rigger::control
