#include "rigger/ros2/conversions.hpp"

#include <algorithm>
#include <iterator>

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

namespace {
// The same sequence, borrowed: the copy does not own (or free) the buffer.
dds_sequence_double borrow(const dds_sequence_double& d) {
  dds_sequence_double out = d;
  out._release = false;
  return out;
}

// The three matrices, the same numbers in both layouts under other names.
void copy_matrices(const double (&k)[9], const double (&r)[9], const double (&p)[12], double (&to_k)[9],
                   double (&to_r)[9], double (&to_p)[12]) {
  std::copy(std::begin(k), std::end(k), std::begin(to_k));
  std::copy(std::begin(r), std::end(r), std::begin(to_r));
  std::copy(std::begin(p), std::end(p), std::begin(to_p));
}
}  // namespace

rigger_vision_CameraInfo to_rigger(const sensor_msgs_msg_dds__CameraInfo_& c) {
  rigger_vision_CameraInfo out{to_rigger(c.header_), c.height_, c.width_, c.distortion_model_, borrow(c.d_), {}, {}, {}};
  copy_matrices(c.k_, c.r_, c.p_, out.k, out.r, out.p);
  return out;
}

sensor_msgs_msg_dds__CameraInfo_ to_ros2(const rigger_vision_CameraInfo& c) {
  sensor_msgs_msg_dds__CameraInfo_ out{};  // no binning, the full image as region of interest
  out.header_ = to_ros2(c.header);
  out.height_ = c.height;
  out.width_ = c.width;
  out.distortion_model_ = c.distortion_model;
  out.d_ = borrow(c.d);
  copy_matrices(c.k, c.r, c.p, out.k_, out.r_, out.p_);
  return out;
}

}  // namespace rigger::ros2
