#pragma once
/// @file
/// The journal server: answers rigger/task/journal_query on rigger/task/journal_reply (riggerctl
/// journal, the console). A query names a task (its timeline) or none (the tasks, newest first);
/// answer_query() bounds every answer (journal_query_limit) and is pure over a Journal, so it is
/// tested without DDS.

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "journal.hpp"
#include "rigger/dds/pubsub.hpp"
#include "rigger/protocol/task.hpp"

namespace rigger::task_controller {

/// Entries a query gets when it asks for none (max_entries 0), and the most any query gets.
inline constexpr std::size_t kDefaultJournalEntries = 1000;
inline constexpr std::size_t kMaxJournalEntries = 10000;

/// The number of entries a query asking for `max_entries` gets.
std::size_t journal_query_limit(std::uint32_t max_entries);

struct JournalAnswer {
  bool ok = true;
  std::string message;  ///< why not ok
  std::vector<JournalRecord> records;
};

/// The timeline of `task_id`, or one "TASK" line per task when it is empty; at most `max_entries`.
JournalAnswer answer_query(const Journal& journal, const std::string& task_id, std::uint32_t max_entries);

class JournalServer {
 public:
  /// @throws DdsError.
  JournalServer(const dds::Participant& participant, const Journal& journal);
  /// Answers every waiting query.
  void take();
  const dds::Reader<rigger_task_JournalQuery>& queries() const { return queries_; }

 private:
  const Journal& journal_;
  dds::Reader<rigger_task_JournalQuery> queries_;
  dds::Writer<rigger_task_JournalReply> replies_;
};

}  // namespace rigger::task_controller
