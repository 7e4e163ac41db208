#include "monitor_registry.hpp"

#include "force_monitor.hpp"
#include "timer_monitor.hpp"
#include "yank_monitor.hpp"

namespace rigger::monitor {

std::vector<std::string> monitor_names() { return {"ForceMonitor", "TimerMonitor", "YankMonitor"}; }

std::unique_ptr<Monitor> make_monitor(std::string_view name) {
  if (name == ForceMonitor::describe().name) return std::make_unique<ForceMonitor>();
  if (name == TimerMonitor::describe().name) return std::make_unique<TimerMonitor>();
  if (name == YankMonitor::describe().name) return std::make_unique<YankMonitor>();
  return nullptr;
}

nlohmann::json monitor_library_json() {
  nlohmann::json skills = nlohmann::json::array();
  for (const auto& name : monitor_names()) skills.push_back(make_monitor(name)->description().to_json());
  return {{"library_version", 1}, {"skills", skills}};
}

}  // namespace rigger::monitor
