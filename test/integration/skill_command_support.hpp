#pragma once
// Writing raw SkillCommands as the controller would, for tests and benchmarks of executors
// (monitor_host, skill_executor) that play the controller themselves.
#include <string>

#include "rigger/dds/conversions.hpp"
#include "rigger/dds/pubsub.hpp"

namespace rigger::testing {

/// Whether a SkillEvent kind ends a run (SUCCESS, FAILURE, STOPPED), unlike ACCEPTED and PROGRESS.
inline bool ends_run(int kind) {
  return kind == rigger_skill_SKILL_EVENT_SUCCESS || kind == rigger_skill_SKILL_EVENT_FAILURE ||
         kind == rigger_skill_SKILL_EVENT_STOPPED;
}

struct SkillCommandFields {
  std::string executor_id, task_id, node_id, skill;
  rigger_skill_SkillCommandKind kind = rigger_skill_SKILL_START;
  std::string params_json = "{}";
  std::string reason = "test";
  std::uint64_t seq = 0;
};

/// Writes the command. A keep-all writer blocks (up to its max_blocking_time) while its history is
/// full of unacknowledged samples — a burst of STARTs meets that — so a timed-out write is retried.
/// Returns the last DDS return code.
inline dds_return_t write_skill_command(const dds::Writer<rigger_skill_SkillCommand>& writer, const SkillCommandFields& f) {
  rigger_skill_SkillCommand c{};
  c.executor_id = dds::wire_string(f.executor_id);
  c.task_id = dds::wire_string(f.task_id);
  c.node_id = dds::wire_string(f.node_id);
  c.skill = dds::wire_string(f.skill);
  c.kind = f.kind;
  c.params_json = dds::wire_string(f.params_json);
  c.reason = dds::wire_string(f.reason);
  c.seq = f.seq;
  c.stamp = dds::wire_now();
  dds_return_t rc = DDS_RETCODE_TIMEOUT;
  for (int attempt = 0; attempt < 50 && rc == DDS_RETCODE_TIMEOUT; ++attempt) rc = writer.write(c);
  return rc;
}

}  // namespace rigger::testing
