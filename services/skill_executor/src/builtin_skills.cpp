#include "builtin_skills.hpp"

#include "rigger/skill_executor/library.hpp"
#include "rigger/skill_executor/settings.hpp"
#include "skills/attach_robot_to_load.hpp"
#include "skills/calibrate_camera.hpp"
#include "skills/collaborative_move_load.hpp"
#include "skills/insert_visually_guided.hpp"
#include "skills/localize.hpp"
#include "skills/move_to.hpp"
#include "skills/pick_place.hpp"
#include "skills/release.hpp"
#include "skills/screw.hpp"

namespace rigger::skill_executor {

SkillRegistry builtin_skills() {
  SkillRegistry registry;
  registry.add<MoveToSkill>();
  registry.add<LocalizeSkill>();
  registry.add<ScrewSkill>();
  registry.add<CollaborativeMoveLoadSkill>();
  registry.add<InsertVisuallyGuidedSkill>();
  registry.add<AttachRobotToLoadSkill>();
  registry.add<ReleaseSkill>();
  registry.add<PickSkill>();
  registry.add<PlaceSkill>();
  registry.add<CalibrateCameraSkill>();
  return registry;
}

SettingsTable<skill_sdk::ExecutorSettings> skill_executor_settings(const std::string& service_id) {
  return skill_sdk::executor_settings(service_id, builtin_skills());
}

nlohmann::json builtin_skill_library_json() {
  const SkillRegistry registry = builtin_skills();
  return registry.library_json(registry.names());
}

}  // namespace rigger::skill_executor
