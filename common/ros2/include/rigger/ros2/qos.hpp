#pragma once
/// @file
/// The QoS profiles of ROS 2 (rmw/qos_profiles.h) that drivers use, as Cyclone QoS. A rigger endpoint
/// on a ROS 2 topic takes the profile its ROS 2 peer uses, so that the two match: a reliable reader
/// never matches a best-effort writer.

#include "rigger/dds/qos.hpp"

namespace rigger::ros2::qos {

/// rmw_qos_profile_sensor_data (rclcpp::SensorDataQoS()): best effort, keep-last 5, volatile. What sensor
/// drivers that favour the newest sample (camera images, many force-torque drivers) publish with.
dds::Qos sensor_data();

/// rmw_qos_profile_default: reliable, keep-last 10, volatile. What a ROS 2 node gets from
/// create_publisher(topic, 10), the common case for states and commands. Which profile a given driver
/// uses varies by driver and version: the bridge's cell configuration names it per topic.
dds::Qos reliable_default();

/// rmw_qos_profile_system_default (rclcpp::SystemDefaultsQoS()) as rmw_cyclonedds resolves it: Cyclone's
/// defaults, i.e. reliable, keep-last 1, volatile. What joint_state_broadcaster publishes /joint_states with.
dds::Qos system_default();

}  // namespace rigger::ros2::qos
