#pragma once
/// @file
/// The topics of camera and tracker (idl/vision.idl), each declared once.

#include <rigger/idl/types.hpp>

#include "rigger/protocol/topic.hpp"

namespace rigger::protocol::vision {

/// camera driver / cell_sim → vision_tracker.
inline constexpr Topic<rigger_vision_Image> kCameraImage{
    "rigger/camera/image", QosProfile::kSensorStream,     "", "camera driver / cell_sim",
    "vision_tracker",      "(sensor_msgs layout, mono8)", ""};

/// cell_sim → vision_tracker (TRACK_ONCE_MODEL), tests and recorders. Same type as the image.
inline constexpr Topic<rigger_vision_Image> kCameraDepth{
    "rigger/camera/depth",
    QosProfile::kSensorStream,
    "",
    "cell_sim (`camera/renderer` mujoco)",
    "vision_tracker (markerless TRACK_ONCE_MODEL), observer",
    "(32FC1: metres along the optical axis, NaN where nothing was seen; the stamp and frame id of the image of "
    "the same frame)",
    ""};

/// camera driver / cell_sim → nothing in rigger: the tracker takes the intrinsics from the cell file.
inline constexpr Topic<rigger_vision_CameraInfo> kCameraInfo{
    "rigger/camera/info",
    QosProfile::kState,
    "",
    "camera driver / cell_sim",
    "none (vision_tracker takes the intrinsics from the cell file)",
    "",
    ""};

/// vision_tracker → world_model, admittance_control.
inline constexpr Topic<rigger_vision_TrackedPose> kTrackerPose{"rigger/tracker/pose",
                                                               QosProfile::kSensorStream,
                                                               "object_id",
                                                               "vision_tracker",
                                                               "world_model, admittance_control",
                                                               "(pose with covariance, quality, tracked, image stamp; a search by model's status code and detail, and NOT_SEEN for a TRACK_ONCE that ended without a pose)",
                                                               ""};

/// skills → vision_tracker.
inline constexpr Topic<rigger_vision_TrackerCommand> kTrackerCommand{"rigger/tracker/command",
                                                                     QosProfile::kCommands,
                                                                     "",
                                                                     "skills",
                                                                     "vision_tracker",
                                                                     "(TRACK_ONCE, TRACK_CONTINUOUS, STOP, TRACK_ONCE_MODEL)",
                                                                     ""};

}  // namespace rigger::protocol::vision
