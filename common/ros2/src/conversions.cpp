#include "rigger/ros2/conversions.hpp"

#include "rigger/dds/conversions.hpp"

namespace rigger::ros2 {

rigger_geometry_Time to_rigger(const builtin_interfaces_msg_dds__Time_& t) {
  return {t.sec_, t.nanosec_};
}
builtin_interfaces_msg_dds__Time_ to_ros2(const rigger_geometry_Time& t) {
  return {t.sec, t.nanosec};
}

rigger_geometry_Header to_rigger(const std_msgs_msg_dds__Header_& h) {
  return {to_rigger(h.stamp_), h.frame_id_};
}
std_msgs_msg_dds__Header_ to_ros2(const rigger_geometry_Header& h) {
  return {to_ros2(h.stamp), h.frame_id};
}

rigger_geometry_Vector3 to_rigger(const geometry_msgs_msg_dds__Vector3_& v) {
  return {v.x_, v.y_, v.z_};
}
geometry_msgs_msg_dds__Vector3_ to_ros2(const rigger_geometry_Vector3& v) {
  return {v.x, v.y, v.z};
}

rigger_geometry_Twist to_rigger(const geometry_msgs_msg_dds__Twist_& t) {
  return {to_rigger(t.linear_), to_rigger(t.angular_)};
}
geometry_msgs_msg_dds__Twist_ to_ros2(const rigger_geometry_Twist& t) {
  return {to_ros2(t.linear), to_ros2(t.angular)};
}

rigger_geometry_Wrench to_rigger(const geometry_msgs_msg_dds__Wrench_& w) {
  return {to_rigger(w.force_), to_rigger(w.torque_)};
}
geometry_msgs_msg_dds__Wrench_ to_ros2(const rigger_geometry_Wrench& w) {
  return {to_ros2(w.force), to_ros2(w.torque)};
}

rigger_sensing_WrenchStamped to_rigger(const geometry_msgs_msg_dds__WrenchStamped_& w) {
  return {to_rigger(w.header_), to_rigger(w.wrench_)};
}
geometry_msgs_msg_dds__WrenchStamped_ to_ros2(const rigger_sensing_WrenchStamped& w) {
  return {to_ros2(w.header), to_ros2(w.wrench)};
}

geometry_msgs_msg_dds__TwistStamped_ to_ros2_twist_stamped(const rigger_geometry_Header& header,
                                                           const rigger_geometry_Twist& twist) {
  return {to_ros2(header), to_ros2(twist)};
}

sensor_msgs_msg_dds__JointState_ to_ros2_joint_state(const rigger_geometry_Header& header, std::vector<char*>& names,
                                                     std::vector<double>& position, std::vector<double>& velocity,
                                                     std::vector<double>& effort) {
  sensor_msgs_msg_dds__JointState_ out{};
  out.header_ = to_ros2(header);
  dds::wire_sequence(out.name_, names);
  dds::wire_sequence(out.position_, position);
  dds::wire_sequence(out.velocity_, velocity);
  dds::wire_sequence(out.effort_, effort);
  return out;
}

}  // namespace rigger::ros2
