// `riggerctl operator`: the human operator's terminal. Shows the pending prompts of
// rigger/operator/prompt and writes the chosen option on rigger/operator/response.
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <functional>
#include <iostream>
#include <map>
#include <memory>
#include <optional>
#include <set>
#include <string>
#include <thread>
#include <tuple>
#include <vector>

#include "commands.hpp"
#include "operator_format.hpp"
#include "rigger/base/time.hpp"
#include "rigger/dds/conversions.hpp"
#include "rigger/dds/event_loop.hpp"
#include "rigger/dds/pubsub.hpp"
#include "rigger/protocol/operator.hpp"

namespace rigger::ctl {
namespace {

struct OperatorOptions {
  bool list = false;
  std::vector<std::string> answers;  // PROMPT_ID=ANSWER
  double timeout_s = -1;             // <0: the mode's default
  std::string operator_id;
  std::string comment;
};

std::string default_operator_id() {
  const char* user = std::getenv("USER");
  char host[256] = {};
  gethostname(host, sizeof host - 1);
  return std::string(user && *user ? user : "operator") + "@" + host;
}

std::string join(const std::vector<std::string>& items) {
  std::string out;
  for (std::size_t i = 0; i < items.size(); ++i) out += (i ? ", " : "") + items[i];
  return out;
}

/// The pending prompts: active ones nobody has answered yet, in order of arrival.
class PromptBoard {
 public:
  enum class Change { kNew, kWithdrawn, kAnswered };
  struct Event {
    Change change;
    std::string prompt_id;
    std::string detail;  // kAnswered: "<answer> by <operator>"
  };

  explicit PromptBoard(dds::Participant& participant)
      : prompts_(participant, protocol::operator_ui::kPrompt),
        responses_(participant, protocol::operator_ui::kResponse) {}

  template <typename OnEvent>
  void attach(dds::EventLoop& loop, OnEvent on_event) {
    loop.on_data(prompts_, [this, on_event] {
      for (const auto& e : take_prompts()) on_event(e);
    });
    loop.on_data(responses_, [this, on_event] {
      for (const auto& e : take_responses()) on_event(e);
    });
  }

  /// Pending prompts in arrival order.
  std::vector<const PromptView*> pending() const {
    std::vector<const PromptView*> out;
    for (const auto& id : order_)
      if (auto it = pending_.find(id); it != pending_.end()) out.push_back(&it->second);
    return out;
  }
  const PromptView* find(const std::string& id) const {
    auto it = pending_.find(id);
    return it == pending_.end() ? nullptr : &it->second;
  }
  /// The participant that asked `id` (its prompt's writer), if it is still known.
  std::optional<dds_guid_t> asked_by(const std::string& id) const {
    auto it = asker_.find(id);
    return it == asker_.end() ? std::nullopt : std::optional<dds_guid_t>(it->second);
  }
  /// Whether `id` was seen withdrawn (and not re-activated since).
  bool withdrawn(const std::string& id) const { return withdrawn_.count(id) > 0; }
  /// Who answered `id`, if anyone did.
  std::optional<std::string> answered_by(const std::string& id) const {
    auto it = answered_.find(id);
    return it == answered_.end() ? std::nullopt : std::optional<std::string>(it->second);
  }
  void mark_answered(const std::string& id, const std::string& detail) {
    answered_[id] = detail;
    remove(id);
  }

 private:
  std::vector<Event> take_prompts() {
    std::vector<Event> events;
    prompts_.take([&](const rigger_operator_ui_OperatorPrompt& p, const dds_sample_info_t& info) {
      PromptView v = operator_protocol::from_wire(p);
      const std::string id = v.prompt_id;
      if (dds_builtintopic_endpoint_t* writer = dds_get_matched_publication_data(prompts_.handle(),
                                                                                 info.publication_handle)) {
        asker_[id] = writer->participant_key;
        dds_builtintopic_free_endpoint(writer);
      }
      if (!v.active) {
        withdrawn_.insert(id);
        if (pending_.count(id)) events.push_back({Change::kWithdrawn, id, ""});
        remove(id);
        return;
      }
      withdrawn_.erase(id);
      if (answered_.count(id)) return;
      const bool is_new = !pending_.count(id);
      pending_[id] = std::move(v);
      if (is_new) {
        order_.push_back(id);
        events.push_back({Change::kNew, id, ""});
      }
    });
    return events;
  }
  std::vector<Event> take_responses() {
    std::vector<Event> events;
    responses_.take([&](const rigger_operator_ui_OperatorResponse& r, const dds_sample_info_t&) {
      const std::string id = dds::to_string(r.prompt_id);
      const std::string detail = dds::to_string(r.answer) + " by " + dds::to_string(r.operator_id);
      if (pending_.count(id)) events.push_back({Change::kAnswered, id, detail});
      mark_answered(id, detail);
    });
    return events;
  }
  void remove(const std::string& id) {
    pending_.erase(id);
    order_.erase(std::remove(order_.begin(), order_.end(), id), order_.end());
  }

  dds::Reader<rigger_operator_ui_OperatorPrompt> prompts_;
  dds::Reader<rigger_operator_ui_OperatorResponse> responses_;
  std::map<std::string, PromptView> pending_;
  std::vector<std::string> order_;
  std::set<std::string> withdrawn_;
  std::map<std::string, std::string> answered_;
  std::map<std::string, dds_guid_t> asker_;  ///< by prompt id: the participant of the prompt's writer
};

class ResponseWriter {
 public:
  ResponseWriter(dds::Participant& participant, std::string operator_id, std::string comment)
      : writer_(participant, protocol::operator_ui::kResponse),
        operator_id_(std::move(operator_id)),
        comment_(std::move(comment)) {}

  /// Writes the answer; returns whether DDS accepted it.
  bool write(const std::string& prompt_id, const std::string& answer) {
    const auto rc = operator_protocol::write_response(writer_, prompt_id, answer, operator_id_, comment_);
    if (rc != DDS_RETCODE_OK) std::fprintf(stderr, "riggerctl: writing the answer failed: %s\n", dds_strretcode(rc));
    return rc == DDS_RETCODE_OK;
  }
  /// Whether a response reader of `participant` (the prompt's asker) matched this writer. An answer
  /// written before that would not reach it: the asker's reader may match later than its prompt did.
  bool reaches(const dds_guid_t& participant) const {
    dds_instance_handle_t handles[64];
    const dds_return_t n = dds_get_matched_subscriptions(writer_.handle(), handles, 64);
    for (dds_return_t i = 0; i < std::min<dds_return_t>(n, 64); ++i) {
      dds_builtintopic_endpoint_t* reader = dds_get_matched_subscription_data(writer_.handle(), handles[i]);
      if (reader == nullptr) continue;
      const bool same = std::memcmp(&reader->participant_key, &participant, sizeof participant) == 0;
      dds_builtintopic_free_endpoint(reader);
      if (same) return true;
    }
    return false;
  }
  dds_entity_t handle() const { return writer_.handle(); }
  /// Waits until every matched reader acknowledged what was written (before the process exits).
  void flush(std::chrono::nanoseconds timeout) { dds_wait_for_acks(writer_.handle(), timeout.count()); }
  const std::string& operator_id() const { return operator_id_; }

 private:
  dds::Writer<rigger_operator_ui_OperatorResponse> writer_;
  std::string operator_id_;
  std::string comment_;
};

void print_list(const PromptBoard& board) {
  const auto pending = board.pending();
  if (pending.empty()) {
    std::printf("no pending prompts\n");
    return;
  }
  for (std::size_t i = 0; i < pending.size(); ++i)
    std::printf("%s", format_prompt(*pending[i], i + 1, pending.size()).c_str());
}

int run_list(const CommonOptions& common, const OperatorOptions& opt) {
  dds::Participant participant(common.domain);
  dds::EventLoop loop(participant);
  PromptBoard board(participant);
  board.attach(loop, [](const PromptBoard::Event&) {});
  // Prompts are state (transient-local): they arrive right after discovery. Collect for the window.
  loop.run_until([] { return false; }, from_seconds(opt.timeout_s < 0 ? 2.0 : opt.timeout_s));
  print_list(board);
  return 0;
}

/// --answer ID=ANSWER…: waits for each prompt, checks the answer is one of its options, writes it.
/// Exit 0 when every answer was written, 1 when a prompt did not show up, was withdrawn or answered
/// already, or an answer is not one of its options.
int run_answers(const CommonOptions& common, const OperatorOptions& opt) {
  std::vector<std::pair<std::string, std::string>> wanted;
  for (const auto& a : opt.answers) {
    auto pair = split_assignment(a);
    if (!pair) {
      std::fprintf(stderr, "riggerctl: --answer '%s': expected PROMPT_ID=ANSWER (ANSWER an option or its number)\n",
                   a.c_str());
      return 2;
    }
    wanted.push_back(*pair);
  }
  dds::Participant participant(common.domain);
  dds::EventLoop loop(participant);
  PromptBoard board(participant);
  board.attach(loop, [](const PromptBoard::Event&) {});
  ResponseWriter writer(participant, opt.operator_id, opt.comment);
  loop.on_status(writer.handle(), DDS_PUBLICATION_MATCHED_STATUS, [] {});  // wakes run_until on a match
  const double timeout_s = opt.timeout_s < 0 ? 10.0 : opt.timeout_s;
  int exit_code = 0;
  for (const auto& [id, input] : wanted) {
    const std::string& prompt_id = id;
    loop.run_until([&] { return board.find(prompt_id) || board.withdrawn(prompt_id) || board.answered_by(prompt_id); },
                   from_seconds(timeout_s));
    const PromptView* p = board.find(prompt_id);
    if (!p) {
      if (auto by = board.answered_by(prompt_id))
        std::fprintf(stderr, "riggerctl: prompt '%s' was answered already (%s)\n", prompt_id.c_str(), by->c_str());
      else if (board.withdrawn(prompt_id))
        std::fprintf(stderr, "riggerctl: prompt '%s' was withdrawn\n", prompt_id.c_str());
      else
        std::fprintf(stderr, "riggerctl: no pending prompt '%s' on %s after %.1f s\n", prompt_id.c_str(),
                     dds::describe_domain(common.domain).c_str(), timeout_s);
      exit_code = 1;
      continue;
    }
    const auto answer = resolve_answer(input, p->options);
    if (!answer) {
      std::fprintf(stderr, "riggerctl: '%s' is not an option of prompt '%s' (options: %s)\n", input.c_str(),
                   prompt_id.c_str(), join(p->options).c_str());
      exit_code = 1;
      continue;
    }
    // The asker's reader may not have matched this writer yet (it saw the prompt's writer first).
    if (const auto asker = board.asked_by(prompt_id);
        asker && !loop.run_until([&] { return writer.reaches(*asker); }, from_seconds(timeout_s))) {
      std::fprintf(stderr, "riggerctl: the asker of prompt '%s' does not read answers after %.1f s\n",
                   prompt_id.c_str(), timeout_s);
      exit_code = 1;
      continue;
    }
    if (!writer.write(prompt_id, *answer)) {
      exit_code = 1;
      continue;
    }
    board.mark_answered(prompt_id, *answer + " by " + writer.operator_id());
    std::printf("answered %s: %s\n", prompt_id.c_str(), answer->c_str());
  }
  writer.flush(std::chrono::seconds(3));
  return exit_code;
}

/// Reads stdin lines on a thread of its own and hands them to the event loop.
class LineReader {
 public:
  LineReader(dds::EventLoop& loop, std::function<void(std::string)> on_line, std::function<void()> on_end)
      : thread_([&loop, on_line, on_end] {
          std::string line;
          while (std::getline(std::cin, line)) loop.post([on_line, line] { on_line(line); });
          loop.post(on_end);
        }) {}
  ~LineReader() { thread_.join(); }  // only destroyed after on_end ran: the thread has finished

 private:
  std::thread thread_;
};

int run_interactive(const CommonOptions& common, const OperatorOptions& opt) {
  dds::Participant participant(common.domain);
  dds::EventLoop loop(participant);
  PromptBoard board(participant);
  ResponseWriter writer(participant, opt.operator_id, opt.comment);
  std::string current;  // the prompt the bare answers go to
  bool quit = false;

  auto show_current = [&] {
    const auto pending = board.pending();
    if (pending.empty()) {
      current.clear();
      std::printf("waiting for prompts on domain %u (Ctrl-D quits)\n", common.domain);
    } else {
      current = pending.front()->prompt_id;
      std::printf("\n%s", format_prompt(*pending.front(), 1, pending.size()).c_str());
      std::printf("answer (number or text%s)> ", pending.size() > 1 ? ", or PROMPT_ID=ANSWER" : "");
    }
    std::fflush(stdout);
  };
  board.attach(loop, [&](const PromptBoard::Event& e) {
    switch (e.change) {
      case PromptBoard::Change::kNew:
        if (current.empty())
          show_current();
        else
          std::printf("\n(new prompt %s queued: %zu pending)\n", e.prompt_id.c_str(), board.pending().size());
        break;
      case PromptBoard::Change::kWithdrawn:
        std::printf("\nprompt %s withdrawn\n", e.prompt_id.c_str());
        if (e.prompt_id == current) show_current();
        break;
      case PromptBoard::Change::kAnswered:
        std::printf("\nprompt %s answered: %s\n", e.prompt_id.c_str(), e.detail.c_str());
        if (e.prompt_id == current) show_current();
        break;
    }
    std::fflush(stdout);
  });
  auto on_line = [&](const std::string& line) {
    std::string id = current;
    std::string input = line;
    if (auto pair = split_assignment(line); pair && board.find(pair->first)) std::tie(id, input) = *pair;
    const PromptView* p = board.find(id);
    if (!p) {
      show_current();
      return;
    }
    const auto answer = resolve_answer(input, p->options);
    if (!answer) {
      if (!input.empty())
        std::printf("'%s' is not an option (type 1-%zu or an option's text)\n", input.c_str(), p->options.size());
      show_current();
      return;
    }
    if (writer.write(id, *answer)) {
      board.mark_answered(id, *answer);
      std::printf("answered %s: %s\n", id.c_str(), answer->c_str());
    }
    show_current();
  };
  show_current();
  LineReader reader(loop, on_line, [&] { quit = true; });
  while (!quit) loop.run_until([&] { return quit; }, std::chrono::hours(24));
  writer.flush(std::chrono::seconds(3));
  std::printf("\n");
  return 0;
}

}  // namespace

void add_operator_command(CLI::App& app, const CommonOptions& common, int& exit_code) {
  auto opt = std::make_shared<OperatorOptions>();
  auto* cmd = app.add_subcommand("operator", "Show pending operator prompts and answer them");
  cmd->add_flag("--list", opt->list, "Print the pending prompts and exit");
  cmd->add_option("--answer", opt->answers,
                  "PROMPT_ID=ANSWER: answer a prompt without asking (ANSWER an option or its number); repeatable")
      ->expected(1)
      ->multi_option_policy(CLI::MultiOptionPolicy::TakeAll);
  cmd->add_option("--timeout", opt->timeout_s,
                  "Seconds: --list collects prompts this long (default 2); --answer waits this long for each "
                  "prompt (default 10)")
      ->check(CLI::Range(0.0, 3600.0));
  cmd->add_option("--operator-id", opt->operator_id, "Who answers (default: $USER@host)");
  cmd->add_option("--comment", opt->comment, "Text sent with the answers");
  cmd->callback([&common, &exit_code, opt] {
    if (opt->operator_id.empty()) opt->operator_id = default_operator_id();
    if (opt->list && !opt->answers.empty()) {
      std::fprintf(stderr, "riggerctl operator: --list and --answer exclude each other\n");
      exit_code = 2;
      return;
    }
    if (opt->list)
      exit_code = run_list(common, *opt);
    else if (!opt->answers.empty())
      exit_code = run_answers(common, *opt);
    else
      exit_code = run_interactive(common, *opt);
  });
}

}  // namespace rigger::ctl
