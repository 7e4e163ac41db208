#pragma once
/// @file
/// The ROS 2 message types (idl/ros2) that rigger endpoints publish or take, registered with rigger's
/// typed readers and writers: `rigger::dds::Reader<geometry_msgs_msg_dds__WrenchStamped_>`.

#include <rigger/ros2/builtin_interfaces.h>
#include <rigger/ros2/geometry_msgs.h>
#include <rigger/ros2/sensor_msgs.h>
#include <rigger/ros2/std_msgs.h>

#include <rigger/idl/types.hpp>

namespace rigger::idl {

RIGGER_IDL_TYPE(geometry_msgs_msg_dds__PoseStamped_)
RIGGER_IDL_TYPE(geometry_msgs_msg_dds__TwistStamped_)
RIGGER_IDL_TYPE(geometry_msgs_msg_dds__WrenchStamped_)
RIGGER_IDL_TYPE(sensor_msgs_msg_dds__JointState_)
RIGGER_IDL_TYPE(sensor_msgs_msg_dds__Image_)
RIGGER_IDL_TYPE(sensor_msgs_msg_dds__CameraInfo_)

}  // namespace rigger::idl
