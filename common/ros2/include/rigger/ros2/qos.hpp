#pragma once
/// @file
/// The QoS profiles of ROS 2 (rmw/qos_profiles.h) that drivers use, as Cyclone QoS. A rigger endpoint
/// on a ROS 2 topic takes the profile its ROS 2 peer uses, so that the two match: a reliable reader
/// never matches a best-effort writer.

#include "rigger/dds/qos.hpp"

namespace rigger::ros2::qos {

/// rmw_qos_profile_sensor_data: best effort, keep-last 5, volatile. Sensor drivers and broadcasters
/// (camera images, force-torque sensor broadcaster) publish with it.
dds::Qos sensor_data();

/// rmw_qos_profile_default: reliable, keep-last 10, volatile. What a ROS 2 node gets when it names
/// only a depth, e.g. joint_state_broadcaster and MoveIt Servo's command topics.
dds::Qos reliable_default();

}  // namespace rigger::ros2::qos
