#include "rigger/ros2/names.hpp"

namespace rigger::ros2 {
namespace {

[[noreturn]] void refuse(std::string_view what, std::string_view name, std::size_t at, std::string_view rule) {
  throw NameError(std::string(what) + " '" + std::string(name) + "' at " + std::to_string(at) + ": " +
                  std::string(rule));
}

bool allowed(char c) {
  return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '_' || c == '/';
}

// ROS 2's rules for a name (rmw_validate_full_topic_name, rcl_validate_topic_name), except that whether
// it must start with '/' is the caller's business.
void validate(std::string_view what, std::string_view name) {
  if (name.empty()) refuse(what, name, 0, "is empty");
  if (name.front() == '~') refuse(what, name, 0, "private names (~) need a node name; give the name in full");
  for (std::size_t i = 0; i < name.size(); ++i) {
    const char c = name[i];
    if (c == '{' || c == '}') refuse(what, name, i, "substitutions ({...}) need a node; give the name in full");
    if (!allowed(c)) refuse(what, name, i, "only letters, digits, '_' and '/' are allowed");
    if (c == '/' && i + 1 < name.size() && name[i + 1] == '/') refuse(what, name, i, "contains '//'");
    const bool token_start = i == 0 || name[i - 1] == '/';
    if (token_start && c >= '0' && c <= '9') refuse(what, name, i, "a name token must not start with a digit");
  }
}

}  // namespace

std::string fully_qualified_topic_name(std::string_view name, std::string_view ros_namespace) {
  validate("ROS 2 topic name", name);
  if (name.back() == '/') refuse("ROS 2 topic name", name, name.size() - 1, "must not end with '/'");
  std::string full;
  if (name.front() == '/') {
    full = name;
  } else {
    validate("ROS 2 namespace", ros_namespace);
    if (ros_namespace.front() != '/') refuse("ROS 2 namespace", ros_namespace, 0, "must be absolute (start with '/')");
    if (ros_namespace.size() > 1 && ros_namespace.back() == '/') {
      refuse("ROS 2 namespace", ros_namespace, ros_namespace.size() - 1, "must not end with '/'");
    }
    full = std::string(ros_namespace);
    if (full != "/") full += '/';
    full += name;
  }
  if (full.size() > kMaxTopicNameLength) {
    throw NameError("ROS 2 topic name '" + full + "' is " + std::to_string(full.size()) +
                    " characters long; ROS 2 allows " + std::to_string(kMaxTopicNameLength));
  }
  return full;
}

std::string dds_topic_name(std::string_view name, std::string_view ros_namespace) {
  return "rt" + fully_qualified_topic_name(name, ros_namespace);
}

}  // namespace rigger::ros2
