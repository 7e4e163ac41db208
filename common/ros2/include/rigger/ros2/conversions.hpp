#pragma once
/// @file
/// ROS 2 messages (idl/ros2) to and from rigger's own wire types, which have the same field layout
/// under rigger's names (idl/geometry.idl, idl/sensing.idl): a field-by-field copy, no unit or frame
/// change. Strings are borrowed, not copied: a converted struct is valid while its source lives (convert,
/// write, drop). Every conversion has a round-trip test (test/conversions_test.cpp).

#include <vector>

#include <rigger/idl/types.hpp>

#include "rigger/ros2/types.hpp"

namespace rigger::ros2 {

rigger_geometry_Time to_rigger(const builtin_interfaces_msg_dds__Time_& t);
builtin_interfaces_msg_dds__Time_ to_ros2(const rigger_geometry_Time& t);

/// Borrows frame_id.
rigger_geometry_Header to_rigger(const std_msgs_msg_dds__Header_& h);
/// Borrows frame_id.
std_msgs_msg_dds__Header_ to_ros2(const rigger_geometry_Header& h);

rigger_geometry_Vector3 to_rigger(const geometry_msgs_msg_dds__Vector3_& v);
geometry_msgs_msg_dds__Vector3_ to_ros2(const rigger_geometry_Vector3& v);
rigger_geometry_Twist to_rigger(const geometry_msgs_msg_dds__Twist_& t);
geometry_msgs_msg_dds__Twist_ to_ros2(const rigger_geometry_Twist& t);
rigger_geometry_Wrench to_rigger(const geometry_msgs_msg_dds__Wrench_& w);
geometry_msgs_msg_dds__Wrench_ to_ros2(const rigger_geometry_Wrench& w);

/// force_torque_sensor_broadcaster's message as rigger's robot wrench (sensor frame). Borrows frame_id.
rigger_sensing_WrenchStamped to_rigger(const geometry_msgs_msg_dds__WrenchStamped_& w);
/// Borrows frame_id.
geometry_msgs_msg_dds__WrenchStamped_ to_ros2(const rigger_sensing_WrenchStamped& w);

/// A TwistStamped (MoveIt Servo's Cartesian command) of `twist` in `header`'s frame. Borrows frame_id.
geometry_msgs_msg_dds__TwistStamped_ to_ros2_twist_stamped(const rigger_geometry_Header& header,
                                                           const rigger_geometry_Twist& twist);

/// A JointState (joint_state_broadcaster's message) in `header`, borrowing frame_id, the names and the three
/// arrays (which must outlive the result and are not released with it).
sensor_msgs_msg_dds__JointState_ to_ros2_joint_state(const rigger_geometry_Header& header, std::vector<char*>& names,
                                                     std::vector<double>& position, std::vector<double>& velocity,
                                                     std::vector<double>& effort);

/// A camera driver's intrinsics as rigger's camera info (binning and region of interest are not carried:
/// rigger's images are full and unbinned; the caller checks them). Borrows frame_id, distortion_model and
/// the coefficients.
rigger_vision_CameraInfo to_rigger(const sensor_msgs_msg_dds__CameraInfo_& c);
/// With no binning and the full image as region of interest. Borrows as to_rigger.
sensor_msgs_msg_dds__CameraInfo_ to_ros2(const rigger_vision_CameraInfo& c);

}  // namespace rigger::ros2
