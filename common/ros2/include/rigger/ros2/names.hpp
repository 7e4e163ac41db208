#pragma once
/// @file
/// ROS 2 topic names and the DDS topic names rmw_cyclonedds gives them: a ROS 2 topic "/wrench" is the
/// DDS topic "rt/wrench" (ROS 2 design, "Topic and Service name mapping to DDS").

#include <cstddef>
#include <stdexcept>
#include <string>
#include <string_view>

namespace rigger::ros2 {

/// A ROS 2 topic name or namespace that ROS 2 would refuse; what() names the name, the offending
/// position and the rule.
class NameError : public std::invalid_argument {
 public:
  using std::invalid_argument::invalid_argument;
};

/// The longest fully qualified topic name ROS 2 accepts (rmw: 255 less 8 for the DDS prefixes).
inline constexpr std::size_t kMaxTopicNameLength = 255 - 8;

/// The fully qualified ROS 2 name of `name`: an absolute name ("/a/b") is kept, a relative one ("b")
/// is put under `ros_namespace` ("/a" or "/" for none). Private names ("~/x") and substitutions ("{node}")
/// need a node, which rigger is not, and are refused. Throws NameError for an empty name, characters
/// other than [A-Za-z0-9_/], "//", a trailing '/', a token starting with a digit, or a result longer
/// than kMaxTopicNameLength; the namespace obeys the same rules and must be absolute.
std::string fully_qualified_topic_name(std::string_view name, std::string_view ros_namespace = "/");

/// The DDS topic name of ROS 2 topic `name` (resolved as fully_qualified_topic_name does): "rt" followed
/// by the fully qualified name, e.g. "/wrench" -> "rt/wrench", ("joint_states", "/arm") ->
/// "rt/arm/joint_states". Throws NameError.
std::string dds_topic_name(std::string_view name, std::string_view ros_namespace = "/");

}  // namespace rigger::ros2
