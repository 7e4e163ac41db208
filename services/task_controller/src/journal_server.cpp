#include "journal_server.hpp"

#include <algorithm>
#include <chrono>

#include "rigger/dds/conversions.hpp"

namespace rigger::task_controller {

std::size_t journal_query_limit(std::uint32_t max_entries) {
  return max_entries == 0 ? kDefaultJournalEntries : std::min<std::size_t>(max_entries, kMaxJournalEntries);
}

JournalAnswer answer_query(const Journal& journal, const std::string& task_id, std::uint32_t max_entries) {
  const std::size_t max = journal_query_limit(max_entries);
  JournalAnswer answer;
  if (task_id.empty()) {
    for (const auto& t : journal.tasks(max))
      answer.records.push_back({t.submitted_s, t.task_id, t.task_id, "TASK", t.state, ""});
  } else {
    answer.records = journal.timeline(task_id, max);
    if (answer.records.empty()) {
      answer.ok = false;
      answer.message = "no such task in the journal";
    }
  }
  return answer;
}

JournalServer::JournalServer(const dds::Participant& participant, const Journal& journal)
    : journal_(journal),
      queries_(participant, protocol::task::kJournalQuery),
      replies_(participant, protocol::task::kJournalReply) {}

void JournalServer::take() {
  queries_.take([this](const rigger_task_JournalQuery& q, const dds_sample_info_t&) {
    const JournalAnswer answer = answer_query(journal_, dds::to_string(q.task_id), q.max_entries);
    std::vector<rigger_task_JournalEntry> entries;
    for (const auto& r : answer.records) {
      rigger_task_JournalEntry e{};
      e.stamp = dds::to_wire(std::chrono::system_clock::time_point(
          std::chrono::duration_cast<std::chrono::system_clock::duration>(std::chrono::duration<double>(r.stamp_s))));
      e.node_id = dds::wire_string(r.node_id);
      e.kind = dds::wire_string(r.kind);
      e.code = dds::wire_string(r.code);
      e.message = dds::wire_string(r.message);
      entries.push_back(e);
    }
    rigger_task_JournalReply reply{};
    reply.client_id = q.client_id;
    reply.request_id = q.request_id;
    reply.ok = answer.ok;
    reply.message = dds::wire_string(answer.message);
    dds::wire_sequence(reply.entries, entries);
    replies_.write(reply);
  });
}

}  // namespace rigger::task_controller
