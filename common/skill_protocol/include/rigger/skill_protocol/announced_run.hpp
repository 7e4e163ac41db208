#pragma once
/// @file
/// A run as an executor announces it on rigger/skill/executors (ExecutorAnnouncement.runs): what a
/// (re)started controller reads to learn which resources runs of an earlier controller still hold.
/// Pure data; the wire conversions are in executor_endpoint.hpp.

#include <string>
#include <vector>

namespace rigger::skill_protocol {

/// One run active on an executor: started and not yet ended by SUCCESS, FAILURE or STOPPED.
struct AnnouncedRun {
  std::string task_id;
  std::string node_id;
  std::string skill;
  std::vector<std::string> resources;  ///< the skill description's `resources`, "$param" resolved
  bool stopping = false;               ///< a SHUTDOWN reached it (from the controller, or CONTROLLER_LOST)
};

inline bool operator==(const AnnouncedRun& a, const AnnouncedRun& b) {
  return a.task_id == b.task_id && a.node_id == b.node_id && a.skill == b.skill && a.resources == b.resources &&
         a.stopping == b.stopping;
}
inline bool operator!=(const AnnouncedRun& a, const AnnouncedRun& b) {
  return !(a == b);
}

}  // namespace rigger::skill_protocol
