#pragma once
/// @file
/// Every idlc-generated wire type, and the trait that maps a C struct to its topic descriptor so the
/// typed templates in rigger/dds can be written once: `rigger::dds::Writer<rigger_task_Recipe>`.

#include <dds/dds.h>

#include <rigger/idl/admittance.h>
#include <rigger/idl/cad.h>
#include <rigger/idl/crane.h>
#include <rigger/idl/geometry.h>
#include <rigger/idl/operator.h>
#include <rigger/idl/robot.h>
#include <rigger/idl/safety.h>
#include <rigger/idl/sensing.h>
#include <rigger/idl/sim.h>
#include <rigger/idl/skill.h>
#include <rigger/idl/system.h>
#include <rigger/idl/task.h>
#include <rigger/idl/vision.h>
#include <rigger/idl/world.h>

namespace rigger::idl {

/// Maps a generated struct to its topic descriptor. Specialised below for every topic type; other IDL
/// libraries register theirs with the same macro (rigger/ros2/types.hpp).
template <typename T>
struct TypeSupport;

#define RIGGER_IDL_TYPE(T)                                                 \
  template <>                                                              \
  struct TypeSupport<T> {                                                  \
    static const dds_topic_descriptor_t* descriptor() { return &T##_desc; } \
    static constexpr const char* name() { return #T; }                     \
  };

RIGGER_IDL_TYPE(rigger_system_ServiceState)
RIGGER_IDL_TYPE(rigger_system_PeerView)
RIGGER_IDL_TYPE(rigger_system_EchoSample)
RIGGER_IDL_TYPE(rigger_task_Recipe)
RIGGER_IDL_TYPE(rigger_task_TaskCommand)
RIGGER_IDL_TYPE(rigger_task_TaskStatus)
RIGGER_IDL_TYPE(rigger_task_NodeStatus)
RIGGER_IDL_TYPE(rigger_task_JournalQuery)
RIGGER_IDL_TYPE(rigger_task_JournalReply)
RIGGER_IDL_TYPE(rigger_skill_SkillCommand)
RIGGER_IDL_TYPE(rigger_skill_SkillEvent)
RIGGER_IDL_TYPE(rigger_skill_ExecutorAnnouncement)
RIGGER_IDL_TYPE(rigger_world_EntityState)
RIGGER_IDL_TYPE(rigger_world_EntityUpdate)
RIGGER_IDL_TYPE(rigger_world_UpdateResult)
RIGGER_IDL_TYPE(rigger_world_EntityChange)
RIGGER_IDL_TYPE(rigger_world_CellRevision)
RIGGER_IDL_TYPE(rigger_world_CellModel)
RIGGER_IDL_TYPE(rigger_world_CellRequest)
RIGGER_IDL_TYPE(rigger_world_CellReply)
RIGGER_IDL_TYPE(rigger_world_WorldQuery)
RIGGER_IDL_TYPE(rigger_world_WorldReply)
RIGGER_IDL_TYPE(rigger_sensing_WrenchStamped)
RIGGER_IDL_TYPE(rigger_sensing_JointState)
RIGGER_IDL_TYPE(rigger_sensing_TwistCommand)
RIGGER_IDL_TYPE(rigger_robot_RobotState)
RIGGER_IDL_TYPE(rigger_robot_MotionCommand)
RIGGER_IDL_TYPE(rigger_robot_MotionStatus)
RIGGER_IDL_TYPE(rigger_robot_GripperCommand)
RIGGER_IDL_TYPE(rigger_robot_GripperState)
RIGGER_IDL_TYPE(rigger_crane_CraneState)
RIGGER_IDL_TYPE(rigger_crane_CraneVelocityCommand)
RIGGER_IDL_TYPE(rigger_crane_CraneControl)
RIGGER_IDL_TYPE(rigger_vision_Image)
RIGGER_IDL_TYPE(rigger_vision_CameraInfo)
RIGGER_IDL_TYPE(rigger_vision_TrackedPose)
RIGGER_IDL_TYPE(rigger_vision_TrackerCommand)
RIGGER_IDL_TYPE(rigger_admittance_AdmittanceCommand)
RIGGER_IDL_TYPE(rigger_admittance_AdmittanceState)
RIGGER_IDL_TYPE(rigger_operator_ui_OperatorPrompt)
RIGGER_IDL_TYPE(rigger_operator_ui_OperatorResponse)
RIGGER_IDL_TYPE(rigger_sim_SimControl)
RIGGER_IDL_TYPE(rigger_sim_SimEvent)
RIGGER_IDL_TYPE(rigger_sim_SimStatus)
RIGGER_IDL_TYPE(rigger_cad_CadRequest)
RIGGER_IDL_TYPE(rigger_cad_CadReply)
RIGGER_IDL_TYPE(rigger_safety_SafeStop)


}  // namespace rigger::idl
