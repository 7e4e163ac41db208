#pragma once
// Large recipes and trees shared by the scale tests and the benchmarks.

#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "rigger/bt/tree_builder.hpp"

namespace rigger::testing {

/// 1 + 9 × groups nodes: a Sequence of `groups` Timeout(Parallel(1, 1, [Sequence[Localize,
/// ObjectLocalized, Pick, Place], YankMonitor, ForceMonitor])), each group on its own object
/// "part<g>". Valid against test/data/scripted_skill_library.json.
inline nlohmann::json big_recipe(std::size_t groups) {
  using Json = nlohmann::json;
  Json children = Json::array();
  for (std::size_t g = 0; g < groups; ++g) {
    const std::string object = "part" + std::to_string(g);
    Json work = {{"type", "Sequence"},
                 {"children",
                  {{{"type", "Skill"}, {"skill", "Localize"}, {"params", {{"object", object}}}},
                   {{"type", "Condition"}, {"condition", "ObjectLocalized"}, {"params", {{"object", object}}}},
                   {{"type", "Skill"}, {"skill", "Pick"}, {"params", {{"object", object}, {"grasp", object + "/top"}}}},
                   {{"type", "Skill"},
                    {"skill", "Place"},
                    {"params", {{"object", object}, {"pose", {{"position_m", {0, 0, 0}}, {"rpy_deg", {0, 0, 0}}}}}}}}}};
    children.push_back({{"type", "Timeout"},
                        {"duration_s", 60},
                        {"child",
                         {{"type", "Parallel"},
                          {"success_threshold", 1},
                          {"failure_threshold", 1},
                          {"children",
                           {work,
                            {{"type", "Monitor"}, {"monitor", "YankMonitor"}},
                            {{"type", "Monitor"}, {"monitor", "ForceMonitor"}, {"params", {{"max_force_n", 200}}}}}}}}});
  }
  return {{"recipe_version", 1}, {"task_id", "big"}, {"root", {{"type", "Sequence"}, {"children", children}}}};
}

/// Parallel(1, 1) of one skill ("root/0") and `monitors` monitors ("root/1" …).
inline bt::TreeSpec skill_beside_monitors(std::size_t monitors) {
  std::vector<bt::build::Node> children{bt::build::skill("CollaborativeMoveLoad")};
  for (std::size_t i = 0; i < monitors; ++i) {
    children.push_back(bt::build::monitor("ForceMonitor"));
  }
  return bt::build::build(bt::build::parallel(1, 1, children));
}

}  // namespace rigger::testing
