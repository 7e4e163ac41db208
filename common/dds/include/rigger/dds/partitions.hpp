#pragma once
/// @file
/// Partitions of the command topic (protocol::skill::command_partition): the QoS of the readers that
/// take skill commands, and the PARTITION policy itself.

#include <string>
#include <vector>

#include "rigger/dds/qos.hpp"

namespace rigger::dds {

/// Puts the endpoint whose QoS is `q` in these partitions ("" is the default one; a reader's name may be a
/// wildcard pattern, e.g. "rigger.executor.*"). Empty: the default partition only.
void set_partitions(Qos& q, const std::vector<std::string>& names);

namespace qos {
/// The command reader of executor `executor_id`: commands(), in the default partition and in the
/// executor's own.
Qos executor_commands(const std::string& executor_id);
/// A reader of every skill command, whichever executor it addresses (tests, tools): commands(), in the
/// default partition and every executor's.
Qos all_commands();
}  // namespace qos

}  // namespace rigger::dds
