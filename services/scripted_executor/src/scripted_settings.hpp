#pragma once
/// @file
/// The scripted executor's configuration (scripted_executor_settings()): the skill library it announces
/// and the behaviour of each skill, monitor and recipe node. Pure C++ (no DDS).

#include <map>
#include <string>

#include <nlohmann/json.hpp>

#include "behaviour.hpp"
#include "rigger/base/settings.hpp"
#include "rigger/scripted_executor/settings.hpp"

namespace rigger::scripted {

struct ScriptedExecutorSettings {
  nlohmann::json library;                  ///< the library file, its "skills" only the announced ones
  std::map<std::string, bool> is_monitor;  ///< every announced name: whether it is a monitor
  Behaviour default_skill;
  Behaviour default_monitor;  ///< {"mode": "run"}
  std::map<std::string, Behaviour> by_skill;
  std::map<std::string, Behaviour> by_node;  ///< by recipe node id
  std::string receipt_trace_path;            ///< empty: no receipt trace
};

}  // namespace rigger::scripted
