#include "config_checks.hpp"

#include <array>
#include <cmath>
#include <sstream>

namespace rigger::control {
namespace {

constexpr std::array<const char*, 6> kAxisNames{"x", "y", "z", "rx", "ry", "rz"};

bool within(double value, Bound bound) {
  return std::isfinite(value) && (bound == Bound::kPositive ? value > 0.0 : value >= 0.0);
}

const char* bound_text(Bound bound) { return bound == Bound::kPositive ? "> 0" : ">= 0"; }

}  // namespace

std::optional<ConfigProblem> check_axes(const Eigen::Ref<const Eigen::VectorXd>& values, const std::string& pointer,
                                        Bound bound, const char* unit) {
  for (Eigen::Index i = 0; i < values.size(); ++i) {
    if (within(values[i], bound)) continue;
    std::ostringstream os;
    os << "expected a finite number " << bound_text(bound) << " (" << unit << ")";
    if (values.size() <= static_cast<Eigen::Index>(kAxisNames.size()))
      os << " for axis " << kAxisNames[static_cast<std::size_t>(i)];
    os << ", got " << values[i];
    return ConfigProblem{pointer + "/" + std::to_string(i), os.str()};
  }
  return std::nullopt;
}

std::optional<ConfigProblem> check_scalar(double value, const std::string& pointer, Bound bound, const char* unit) {
  if (within(value, bound)) return std::nullopt;
  std::ostringstream os;
  os << "expected a finite number " << bound_text(bound) << " (" << unit << "), got " << value;
  return ConfigProblem{pointer, os.str()};
}

std::optional<ConfigProblem> check_finite(const Eigen::Ref<const Eigen::VectorXd>& values, const std::string& pointer,
                                          const char* unit) {
  for (Eigen::Index i = 0; i < values.size(); ++i)
    if (!std::isfinite(values[i]))
      return ConfigProblem{pointer + "/" + std::to_string(i), std::string("expected a finite number (") + unit + ")"};
  return std::nullopt;
}

std::optional<ConfigProblem> prefixed(std::optional<ConfigProblem> problem, const std::string& prefix) {
  if (problem) problem->pointer = prefix + problem->pointer;
  return problem;
}

}  // namespace rigger::control
