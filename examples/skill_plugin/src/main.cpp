// nudge_skills: a skill executor hosting the Nudge skill, built against the installed rigger SDK.
#include "nudge.hpp"
#include "rigger/skill_sdk/executor.hpp"

int main(int argc, char** argv) {
  rigger::skill_sdk::SkillRegistry skills;
  skills.add<example::NudgeSkill>();
  return rigger::skill_sdk::run_executor(argc, argv, {"nudge_skills", "Hosts the example Nudge skill."},
                                         std::move(skills));
}
