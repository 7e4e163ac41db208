#include "joint_states.hpp"

#include <cmath>
#include <stdexcept>

namespace rigger::ros2_bridge {

std::string_view joint_state_verdict_name(JointStateVerdict verdict) {
  switch (verdict) {
    case JointStateVerdict::kOk:
      return "ok";
    case JointStateVerdict::kLayout:
      return "layout";
    case JointStateVerdict::kDuplicateJoint:
      return "duplicate_joint";
    case JointStateVerdict::kUnknownJoint:
      return "unknown_joint";
    case JointStateVerdict::kMissingJoint:
      return "missing_joint";
    case JointStateVerdict::kNotFinite:
      return "not_finite";
  }
  return "unknown";
}

JointMap::JointMap(std::vector<std::string> chain, std::vector<std::string> ignored) : chain_(std::move(chain)) {
  const auto add = [&](const std::string& name, int index) {
    if (name.empty()) throw std::invalid_argument("a joint name is empty");
    if (!index_.emplace(name, index).second) throw std::invalid_argument("joint '" + name + "' is named twice");
  };
  for (std::size_t i = 0; i < chain_.size(); ++i) add(chain_[i], static_cast<int>(i));
  for (const std::string& name : ignored) add(name, -1);
}

ChainJoints JointMap::map(const std::vector<std::string_view>& names, const double* positions,
                          std::size_t position_count, const double* velocities, std::size_t velocity_count) const {
  ChainJoints out;
  const auto refuse = [&](JointStateVerdict verdict, std::string detail) {
    out.verdict = verdict;
    out.detail = std::move(detail);
    return out;
  };
  if (position_count != names.size() || velocity_count != names.size()) {
    return refuse(JointStateVerdict::kLayout,
                  "names=" + std::to_string(names.size()) + " positions=" + std::to_string(position_count) +
                      " velocities=" + std::to_string(velocity_count) + " (all must be equal)");
  }
  const auto n = static_cast<Eigen::Index>(chain_.size());
  out.position_rad.resize(n);
  out.velocity_radps.resize(n);
  std::vector<bool> seen(chain_.size(), false);
  std::vector<std::string_view> ignored_names;  // a repeated ignored joint is refused too
  for (std::size_t k = 0; k < names.size(); ++k) {
    const auto it = index_.find(std::string(names[k]));
    if (it == index_.end())
      return refuse(JointStateVerdict::kUnknownJoint,
                    "joint '" + std::string(names[k]) + "' is neither one of the arm's joints nor ignored");
    if (it->second < 0) {
      for (std::string_view earlier : ignored_names)
        if (earlier == names[k]) return refuse(JointStateVerdict::kDuplicateJoint, "joint '" + it->first + "' twice");
      ignored_names.push_back(names[k]);
      continue;
    }
    const auto i = static_cast<std::size_t>(it->second);
    if (seen[i]) return refuse(JointStateVerdict::kDuplicateJoint, "joint '" + it->first + "' twice");
    seen[i] = true;
    if (!std::isfinite(positions[k]) || !std::isfinite(velocities[k])) {
      return refuse(JointStateVerdict::kNotFinite, "joint '" + it->first +
                                                       "' position=" + std::to_string(positions[k]) +
                                                       " velocity=" + std::to_string(velocities[k]));
    }
    out.position_rad[static_cast<Eigen::Index>(i)] = positions[k];
    out.velocity_radps[static_cast<Eigen::Index>(i)] = velocities[k];
  }
  for (std::size_t i = 0; i < chain_.size(); ++i)
    if (!seen[i]) return refuse(JointStateVerdict::kMissingJoint, "joint '" + chain_[i] + "' is missing");
  return out;
}

}  // namespace rigger::ros2_bridge
