// riggerctl status and log: the task controller's journal, asked over rigger/task/journal_*.
#include <unistd.h>

#include <chrono>
#include <cstdio>

#include "rigger/base/time.hpp"
#include "rigger/dds/conversions.hpp"
#include "rigger/dds/sequences.hpp"
#include "task_support.hpp"

namespace rigger::ctl::tasks {

JournalAnswer ask_journal(JournalTopics& topics, dds::EventLoop& loop, const std::string& task_id, double timeout_s,
                          std::uint64_t request_id) {
  JournalAnswer answer;
  auto& queries = topics.queries;
  auto& replies = topics.replies;
  if (!queries.wait_for_readers(1, from_seconds(timeout_s)) ||
      !replies.wait_for_writers(1, from_seconds(timeout_s)))
    return answer;
  const std::string client = "riggerctl-" + std::to_string(::getpid());
  loop.on_data(replies, [&] {
    replies.take([&](const rigger_task_JournalReply& rep, const dds_sample_info_t&) {
      if (answer.answered || dds::to_string(rep.client_id) != client || rep.request_id != request_id) return;
      answer.answered = true;
      answer.ok = rep.ok;
      answer.message = dds::to_string(rep.message);
      for (const auto& e : dds::elements(rep.entries))
        answer.lines.push_back({e.stamp, dds::to_string(e.node_id), dds::to_string(e.kind), dds::to_string(e.code),
                                dds::to_string(e.message)});
    });
  });
  rigger_task_JournalQuery q{};
  q.client_id = dds::wire_string(client);
  q.request_id = request_id;
  q.task_id = dds::wire_string(task_id);
  q.max_entries = 1000;
  // Matching is not symmetric: our reply reader can see the controller's reply writer before that
  // writer has seen our reader, and a reply written in that window reaches nobody (replies are
  // volatile). So the query is sent again, with the same id, until an answer comes; the controller
  // answers each copy, and copies after the first answer are ignored here.
  queries.write(q);
  const auto resend = loop.every(std::chrono::milliseconds(500), [&] { queries.write(q); });
  loop.run_until([&] { return answer.answered; }, from_seconds(timeout_s));
  loop.cancel(resend);
  loop.on_data(replies, [&replies] { replies.take([](const rigger_task_JournalReply&, const dds_sample_info_t&) {}); });
  return answer;
}

int journal_failure(const JournalAnswer& answer, const CommonOptions& common, double timeout_s,
                    const std::string& refusal) {
  if (!answer.answered) {
    std::fprintf(stderr, "riggerctl: no task controller on %s answered within %.1f s\n",
                 dds::describe_domain(common.domain).c_str(), timeout_s);
    return kExitNoController;
  }
  if (answer.ok) return 0;
  if (refusal.empty())
    std::fprintf(stderr, "riggerctl: %s\n", answer.message.c_str());
  else
    std::fprintf(stderr, "riggerctl: %s (%s)\n", refusal.c_str(), answer.message.c_str());
  return kExitFailed;
}

int journal_query(const CommonOptions& common, const std::string& task_id, double timeout_s) {
  dds::Participant participant(common.domain);
  JournalTopics topics(participant);
  dds::EventLoop loop(participant);
  const JournalAnswer answer = ask_journal(topics, loop, task_id, timeout_s);
  if (const int failed = journal_failure(answer, common, timeout_s, "")) return failed;
  if (task_id.empty()) std::printf("%-32s %-12s %s\n", "TASK", "STATE", "SUBMITTED (UTC)");
  for (const auto& e : answer.lines) {
    if (task_id.empty())
      std::printf("%-32s %-12s %s\n", e.node_id.c_str(), e.code.c_str(), format_wall(e.stamp).c_str());
    else
      std::printf("%s  %-14s %-16s %-12s %s\n", format_wall(e.stamp).c_str(), e.kind.c_str(), e.node_id.c_str(),
                  e.code.c_str(), e.message.c_str());
  }
  return 0;
}

}  // namespace rigger::ctl::tasks
