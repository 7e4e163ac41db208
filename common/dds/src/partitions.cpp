#include "rigger/dds/partitions.hpp"

#include "rigger/protocol/skill.hpp"

namespace rigger::dds {

void set_partitions(Qos& q, const std::vector<std::string>& names) {
  std::vector<const char*> ps;
  ps.reserve(names.size());
  for (const auto& n : names) ps.push_back(n.c_str());
  dds_qset_partition(q.get(), static_cast<uint32_t>(ps.size()), ps.data());
}

namespace qos {

Qos executor_commands(const std::string& executor_id) {
  Qos q = commands();
  const std::string own = protocol::skill::command_partition(executor_id);
  set_partitions(q, own.empty() ? std::vector<std::string>{""} : std::vector<std::string>{"", own});
  return q;
}

Qos all_commands() {
  Qos q = commands();
  set_partitions(q, {"", protocol::skill::kCommandPartitionPattern});
  return q;
}

}  // namespace qos
}  // namespace rigger::dds
