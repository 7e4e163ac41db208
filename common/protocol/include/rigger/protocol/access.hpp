#pragma once
/// @file
/// Who may write and read which topic, per DDS Security identity: the one table the permissions
/// documents are generated from (`rigger-topic-catalog --permissions`, deploy/security/make-pki,
/// docs/security.md). An identity is a role, not a process: every service of deploy/compose.yaml has one
/// of its own name, the user tools have theirs (riggerctl, console), and a test or a second instance of
/// a service runs under the identity of the role it plays.
///
/// The grants follow what each program opens (a writer or reader it creates without permission makes it
/// fail at start-up, with Cyclone's "not allowed by security" error naming the topic), so a change in
/// the topics a program opens is a change here too.

#include <string>
#include <vector>

namespace rigger::protocol {

/// One identity's grant: the topics it may publish and subscribe to (topic names, exact).
struct Grant {
  std::string identity;     ///< certificate CN and the name of its folder in the PKI, e.g. "task_controller"
  std::string description;  ///< who holds it
  std::vector<std::string> publish;
  std::vector<std::string> subscribe;
};

/// Every identity, in a fixed order. Thread-safe (built once).
const std::vector<Grant>& access_table();
/// The grant of `identity`, or nullptr.
const Grant* find_grant(const std::string& identity);

/// The table as lines `<identity> publish|subscribe <topic>`, the input of deploy/security/make-pki.
std::string access_table_lines();

}  // namespace rigger::protocol
