#pragma once
/// @file
/// A ROS 2 driver's joint states (sensor_msgs/JointState fields) checked and put in the arm's chain order.
/// JointState's order is the driver's (joint_state_broadcaster's is not even stable across versions), so
/// joints are found by name. Pure: no DDS, no wire types. Not thread-safe.

#include <cstddef>
#include <string>
#include <string_view>
#include <unordered_map>
#include <vector>

#include <Eigen/Core>

namespace rigger::ros2_bridge {

/// Why a JointState cannot become a robot state (kOk when it can).
enum class JointStateVerdict {
  kOk,
  kLayout,          ///< position or velocity not as long as name (velocity must be given)
  kDuplicateJoint,  ///< a name twice
  kUnknownJoint,    ///< a name neither in the arm's joints nor in the ignored ones
  kMissingJoint,    ///< an arm joint not in the message
  kNotFinite,       ///< an arm joint's position or velocity NaN or infinite
};
/// "ok", "layout", "duplicate_joint", "unknown_joint", "missing_joint", "not_finite".
std::string_view joint_state_verdict_name(JointStateVerdict verdict);

/// The arm's joints in chain order, with positions (rad) and velocities (rad/s).
struct ChainJoints {
  JointStateVerdict verdict = JointStateVerdict::kOk;
  std::string detail;  ///< on a refusal: which joint and what, e.g. "joint 'joint_a3' is missing"
  Eigen::VectorXd position_rad;
  Eigen::VectorXd velocity_radps;
};

/// Maps a JointState's joints by name onto the arm's chain order.
class JointMap {
 public:
  /// `chain`: the arm's joint names in chain order; `ignored`: names the driver also publishes that are
  /// not the arm's (e.g. a gripper's finger joints). @throws std::invalid_argument on an empty or
  /// repeated name, or a name in both lists.
  JointMap(std::vector<std::string> chain, std::vector<std::string> ignored);

  std::size_t size() const { return chain_.size(); }
  const std::vector<std::string>& chain() const { return chain_; }

  /// Checks one message: `names` (name_), `positions` (position_), `velocities` (velocity_), each of
  /// the given count. Efforts are not used. The result's vectors are chain-ordered on kOk.
  ChainJoints map(const std::vector<std::string_view>& names, const double* positions, std::size_t position_count,
                  const double* velocities, std::size_t velocity_count) const;

 private:
  std::vector<std::string> chain_;
  std::unordered_map<std::string, int> index_;  // name → chain index, or -1 for an ignored joint
};

}  // namespace rigger::ros2_bridge
