// riggerctl's task commands: validate (offline), run, status, tree, skills, cancel, pause, resume, log.
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <sstream>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

#include "commands.hpp"
#include "quiet_matching.hpp"
#include "rigger/base/bounded_json.hpp"
#include "rigger/recipe/recipe_validator.hpp"
#include "rigger/base/install.hpp"
#include "rigger/base/time.hpp"
#include "rigger/dds/conversions.hpp"
#include "rigger/protocol/task_names.hpp"
#include "rigger/dds/event_loop.hpp"
#include "rigger/dds/pubsub.hpp"
#include "rigger/executor/executor_endpoint.hpp"
#include "rigger/protocol/skill.hpp"
#include "rigger/protocol/task.hpp"
#include "rigger/skill/skill_library.hpp"
#include "run_display.hpp"

namespace rigger::ctl {
namespace {

using protocol::task::node_state_name;
using protocol::task::task_state_name;

using Clock = std::chrono::steady_clock;

constexpr int kExitFailed = 1;
constexpr int kExitNoController = 3;

bool task_terminal(int s) {
  return s == rigger_task_TASK_REJECTED || s == rigger_task_TASK_SUCCEEDED || s == rigger_task_TASK_FAILED ||
         s == rigger_task_TASK_CANCELED;
}

std::int64_t wire_ns(const rigger_geometry_Time& t) { return static_cast<std::int64_t>(t.sec) * 1000000000LL + t.nanosec; }

std::string format_wall(const rigger_geometry_Time& t) {
  const std::time_t secs = static_cast<std::time_t>(t.sec);
  std::tm tm{};
  gmtime_r(&secs, &tm);
  char buf[64];
  std::snprintf(buf, sizeof buf, "%02d:%02d:%02d.%03u", tm.tm_hour, tm.tm_min, tm.tm_sec, t.nanosec / 1000000U);
  return buf;
}

/// A node's line in the live tree, indented by depth.
struct NodeLine {
  std::string type, name, state, code, message, executor;
  double progress = -1;
};

std::string node_line(const std::string& id, const NodeLine& n) {
  const auto depth = static_cast<std::size_t>(std::count(id.begin(), id.end(), '/'));
  std::string out(2 * depth, ' ');
  out += id + " " + n.type;
  if (!n.name.empty()) out += " \"" + n.name + "\"";
  out += "  " + n.state;
  if (n.progress >= 0 && (n.state == "RUNNING" || n.state == "STOPPING")) {  // a finished node's is history
    char buf[32];
    std::snprintf(buf, sizeof buf, " %3.0f%%", n.progress * 100.0);
    out += buf;
  }
  if (!n.executor.empty()) out += "  @" + n.executor;
  if (!n.code.empty()) out += "  " + n.code;
  if (!n.message.empty()) out += ": " + n.message;
  return out;
}

NodeUpdate to_update(const rigger_task_NodeStatus& s) {
  NodeUpdate u;
  u.id = dds::to_string(s.node_id);
  u.type = dds::to_string(s.node_type);
  u.name = dds::to_string(s.name);
  u.state = node_state_name(s.state);
  u.code = dds::to_string(s.code);
  u.message = dds::to_string(s.message);
  u.executor = dds::to_string(s.executor_id);
  u.progress_text = dds::to_string(s.progress_text);
  u.progress = s.progress;
  u.started_s = static_cast<double>(wire_ns(s.started)) * 1e-9;
  u.finished_s = static_cast<double>(wire_ns(s.finished)) * 1e-9;
  return u;
}

NodeLine to_line(const rigger_task_NodeStatus& s) {
  return {dds::to_string(s.node_type), dds::to_string(s.name), node_state_name(s.state), dds::to_string(s.code),
          dds::to_string(s.message), dds::to_string(s.executor_id), s.progress};
}

std::string read_file(const std::string& path, std::string& error) {
  std::ifstream in(path, std::ios::binary);
  if (!in) {
    error = "cannot open " + path;
    return {};
  }
  std::ostringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

// --- validate ---

int validate(const std::string& file, const std::string& library_file) {
  skill::SkillLibrary library;
  try {
    library = skill::SkillLibrary::load_file(library_file);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "riggerctl: skill library %s: %s\n", library_file.c_str(), e.what());
    return 2;
  }
  recipe::RecipeValidator validator(std::move(library));
  const auto result = validator.validate_file(file);
  if (result.ok()) {
    std::printf("%s: valid (%zu nodes)\n", file.c_str(), result.recipe->tree.nodes.size());
    return 0;
  }
  for (const auto& e : result.errors)
    std::printf("%s: %s: %s\n", file.c_str(), e.pointer.empty() ? "(document)" : e.pointer.c_str(), e.message.c_str());
  return 1;
}

// --- run ---

struct RunOptions {
  std::string file;
  std::string task_id;
  double timeout_s = 0;  // 0: no limit
  double match_timeout_s = 10;
  bool quiet = false;
};

int run_recipe(const CommonOptions& common, const RunOptions& opt) {
  std::string error;
  std::string text = read_file(opt.file, error);
  if (!error.empty()) {
    std::fprintf(stderr, "riggerctl: %s\n", error.c_str());
    return 2;
  }
  if (text.size() > recipe::kMaxRecipeBytesCeiling) {
    std::fprintf(stderr,
                 "riggerctl: %s: %.1f MB is more than any task controller accepts (max_recipe_bytes is at most "
                 "%zu MB, 4 MB by default); nothing was sent\n",
                 opt.file.c_str(), static_cast<double>(text.size()) / (1024.0 * 1024.0),
                 recipe::kMaxRecipeBytesCeiling / (1024U * 1024U));
    return kExitFailed;
  }
  std::string task_id = opt.task_id;
  {
    // Bounded like the controller's own parse; a bad file goes on unchanged, for the controller's validator to explain.
    auto parsed = parse_json_bounded(text, JsonLimits{recipe::kMaxRecipeBytesCeiling, recipe::Limits{}.max_depth});
    auto& doc = parsed.value;
    if (parsed.ok() && doc.is_object()) {
      if (!task_id.empty()) {
        doc["task_id"] = task_id;  // a new id for a re-run of the same file
        text = doc.dump(2);
      } else if (doc.contains("task_id") && doc["task_id"].is_string()) {
        task_id = doc["task_id"].get<std::string>();
      }
    }
  }
  if (task_id.empty()) task_id = std::filesystem::path(opt.file).stem().string();

  dds::Participant participant(common.domain);
  dds::EventLoop loop(participant);
  dds::Writer<rigger_task_Recipe> recipes(participant, protocol::task::kRecipe);
  dds::Reader<rigger_task_TaskStatus> statuses(participant, protocol::task::kStatus);
  dds::Reader<rigger_task_NodeStatus> nodes(participant, protocol::task::kNodeStatus, dds::qos::state_changes());

  // Also wait for the controller's status writers: a state change published before they matched
  // would reach us only as the latest state (state QoS keeps one sample per node), not as a line.
  const auto matched = [&](auto& reader) {
    return reader.wait_for_writers(1, from_seconds(opt.match_timeout_s));
  };
  if (!recipes.wait_for_readers(1, from_seconds(opt.match_timeout_s)) || !matched(statuses) || !matched(nodes)) {
    std::fprintf(stderr, "riggerctl: no task controller on %s (waited %.1f s)\n",
                 dds::describe_domain(common.domain).c_str(), opt.match_timeout_s);
    return kExitNoController;
  }
  const std::int64_t sent_ns = to_unix_ns(std::chrono::system_clock::now());
  std::map<std::string, NodeLine> tree;
  RunDisplay display(!opt.quiet && ::isatty(STDOUT_FILENO) != 0);
  bool finished = false;
  int final_state = -1;
  std::string code, message, failed_node;
  std::vector<std::pair<std::string, std::string>> errors;

  loop.on_data(nodes, [&] {
    // A take returns samples grouped by node (instance), not in the order they were written: the
    // controller writes a burst of changes together (a child's result, then its parent's). Shown in
    // the order of their stamps, they read as they happened.
    struct Change {
      std::int64_t stamp_ns;
      std::string id;
      NodeLine line;
      NodeUpdate update;
    };
    std::vector<Change> changes;
    nodes.take([&](const rigger_task_NodeStatus& s, const dds_sample_info_t&) {
      if (dds::to_string(s.task_id) != task_id || wire_ns(s.stamp) < sent_ns) return;
      changes.push_back({wire_ns(s.stamp), dds::to_string(s.node_id), to_line(s), to_update(s)});
    });
    std::stable_sort(changes.begin(), changes.end(),
                     [](const Change& a, const Change& b) { return a.stamp_ns < b.stamp_ns; });
    for (auto& c : changes) {
      tree[c.id] = std::move(c.line);
      const std::string shown = display.update(c.update);
      if (!opt.quiet) std::fputs(shown.c_str(), stdout);
    }
    std::fflush(stdout);
  });
  loop.on_data(statuses, [&] {
    statuses.take([&](const rigger_task_TaskStatus& s, const dds_sample_info_t&) {
      // Transient-local: an old status of the same id may arrive first; only ours counts.
      if (dds::to_string(s.task_id) != task_id || wire_ns(s.stamp) < sent_ns) return;
      if (!task_terminal(s.state)) {  // the end is reported below, once
        std::printf("task %s %s\n", task_id.c_str(), task_state_name(s.state));
        std::fflush(stdout);
        return;
      }
      finished = true;
      final_state = s.state;
      code = dds::to_string(s.code);
      message = dds::to_string(s.message);
      failed_node = dds::to_string(s.failed_node);
      for (uint32_t i = 0; i < s.errors._length; ++i)
        errors.emplace_back(dds::to_string(s.errors._buffer[i].pointer), dds::to_string(s.errors._buffer[i].message));
    });
  });

  rigger_task_Recipe r{};
  const std::string submitter = "riggerctl";
  r.task_id = dds::wire_string(task_id);
  r.recipe_json = dds::wire_string(text);
  r.submitter = dds::wire_string(submitter);
  r.stamp = dds::wire_now();
  if (const dds_return_t rc = recipes.write(r); rc != DDS_RETCODE_OK) {
    std::fprintf(stderr, "riggerctl: publishing the recipe (%.1f MB) failed: %s%s\n",
                 static_cast<double>(text.size()) / (1024.0 * 1024.0), dds_strretcode(rc),
                 rc == DDS_RETCODE_TIMEOUT ? " (the controller did not take it in time)" : "");
    return kExitFailed;
  }
  const auto limit = opt.timeout_s > 0 ? from_seconds(opt.timeout_s) : from_seconds(365.0 * 24 * 3600);
  if (!loop.run_until([&] { return finished; }, limit)) {
    std::fprintf(stderr, "riggerctl: task %s did not finish within %.1f s (it keeps running; riggerctl cancel %s)\n",
                 task_id.c_str(), opt.timeout_s, task_id.c_str());
    return kExitFailed;
  }
  const double wall_s = static_cast<double>(to_unix_ns(std::chrono::system_clock::now()) - sent_ns) * 1e-9;
  if (!opt.quiet && display.skills_run() > 0) std::printf("%s", display.durations(wall_s).c_str());
  if (final_state == rigger_task_TASK_SUCCEEDED) {
    std::printf("task %s SUCCEEDED\n", task_id.c_str());
    return 0;
  }
  std::fprintf(stderr, "task %s %s", task_id.c_str(), task_state_name(final_state));
  if (!failed_node.empty()) {
    auto it = tree.find(failed_node);
    std::fprintf(stderr, " at %s", failed_node.c_str());
    if (it != tree.end() && !it->second.name.empty()) std::fprintf(stderr, " (%s)", it->second.name.c_str());
  }
  std::fprintf(stderr, ": %s %s\n", code.c_str(), message.c_str());
  for (const auto& [pointer, msg] : errors) std::fprintf(stderr, "  %s: %s\n", pointer.c_str(), msg.c_str());
  return kExitFailed;
}

// --- journal queries (status, log) ---

/// One journal line as the controller sent it.
struct JournalLine {
  rigger_geometry_Time stamp{};
  std::string node_id, kind, code, message;
};

/// The controller's answer to a journal query: ok, or the controller's reason in `message`.
struct JournalAnswer {
  bool answered = false;  ///< false: no controller matched or answered within the timeout
  bool ok = false;
  std::string message;
  std::vector<JournalLine> lines;
};

/// The journal's query writer and reply reader; declare it before the EventLoop that asks through it.
struct JournalTopics {
  explicit JournalTopics(dds::Participant& participant)
      : queries(participant, protocol::task::kJournalQuery.name, dds::qos::commands()),
        replies(participant, protocol::task::kJournalReply.name, dds::qos::events()) {}
  dds::Writer<rigger_task_JournalQuery> queries;
  dds::Reader<rigger_task_JournalReply> replies;
};

/// Asks the controller's journal for `task_id`'s timeline ("" : the task list) and waits for the answer.
/// A second question of the same run takes a new `request_id` (late copies of an earlier answer are
/// then told apart).
JournalAnswer ask_journal(JournalTopics& topics, dds::EventLoop& loop, const std::string& task_id, double timeout_s,
                          std::uint64_t request_id = 1) {
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
      for (uint32_t i = 0; i < rep.entries._length; ++i) {
        const auto& e = rep.entries._buffer[i];
        answer.lines.push_back({e.stamp, dds::to_string(e.node_id), dds::to_string(e.kind), dds::to_string(e.code),
                                dds::to_string(e.message)});
      }
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

/// When `answer` is unusable: prints why — no controller answered, or the controller's reason headed
/// by `refusal` ("" for the reason alone) — and returns the exit code; 0 when it is usable.
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

// --- tree ---

int show_tree(const CommonOptions& common, const std::string& task_id, double timeout_s) {
  dds::Participant participant(common.domain);
  dds::Reader<rigger_task_NodeStatus> nodes(participant, protocol::task::kNodeStatus);
  JournalTopics topics(participant);
  dds::EventLoop loop(participant);
  // Node status is transient-local, but it arrives some time after the reader matched (Cyclone's
  // wait_for_historical_data does not wait for transient-local data). The journal says which nodes
  // ever changed state, i.e. which statuses to wait for.
  const JournalAnswer journal = ask_journal(topics, loop, task_id, timeout_s);
  if (const int failed = journal_failure(journal, common, timeout_s, "no node status for task " + task_id))
    return failed;
  std::set<std::string> expected;
  for (const auto& l : journal.lines)
    if (l.kind == "NODE" && !l.node_id.empty()) expected.insert(l.node_id);
  std::map<std::string, NodeLine> tree;
  const auto have_all = [&] {
    return std::all_of(expected.begin(), expected.end(), [&](const std::string& id) { return tree.count(id) > 0; });
  };
  loop.on_data(nodes, [&] {
    nodes.take([&](const rigger_task_NodeStatus& s, const dds_sample_info_t&) {
      if (dds::to_string(s.task_id) == task_id) tree[dds::to_string(s.node_id)] = to_line(s);
    });
  });
  const bool complete = loop.run_until(have_all, from_seconds(timeout_s));
  if (tree.empty()) {
    std::fprintf(stderr, "riggerctl: no node status for task %s\n", task_id.c_str());
    return kExitFailed;
  }
  // Pre-order: ids compare by their numeric path ("root/2" before "root/10").
  std::vector<std::pair<std::vector<long>, std::string>> order;
  for (const auto& [id, n] : tree) {
    std::vector<long> path;
    for (std::size_t slash = id.find('/'); slash != std::string::npos; slash = id.find('/', slash + 1))
      path.push_back(std::strtol(id.c_str() + slash + 1, nullptr, 10));
    order.emplace_back(std::move(path), id);
  }
  std::sort(order.begin(), order.end());
  for (const auto& [path, id] : order) std::printf("%s\n", node_line(id, tree.at(id)).c_str());
  if (!complete)
    std::fprintf(stderr, "riggerctl: %zu of %zu nodes have no status (the controller restarted since?)\n",
                 expected.size() - std::min(expected.size(), tree.size()), expected.size());
  return 0;
}

// --- skills ---

std::string pad(const std::string& s, std::size_t width) {
  return s.size() >= width ? s : s + std::string(width - s.size(), ' ');
}

/// One executor's lines for `skills`: its id, pid and host, then each description with its parameters.
std::string describe_executor(const rigger_skill_ExecutorAnnouncement& a) {
  std::string out;
  char line[512];
  std::snprintf(line, sizeof line, "%s (pid %d on %s)\n", dds::to_string(a.executor_id).c_str(), a.pid,
                dds::to_string(a.host).c_str());
  out += line;
  JsonParseResult parsed = parse_json_bounded(dds::to_string(a.library_json));  // from an executor: bounded
  if (!parsed.ok() || !parsed.value.is_object() || !parsed.value.contains("skills")) return out;
  const nlohmann::json& lib = parsed.value;
  for (const auto& d : lib["skills"]) {
    std::string params;
    if (d.contains("params"))
      for (const auto& p : d["params"]) {
        params += params.empty() ? "" : ", ";
        params += p.value("name", "?") + ":" + p.value("type", "?");
        if (p.contains("unit")) params += "[" + p["unit"].get<std::string>() + "]";
        if (p.contains("default")) params += "=" + p["default"].dump();
      }
    out += "  " + pad(d.value("kind", "skill"), 9) + " " + pad(d.value("name", "?"), 28) + " (" + params + ")\n";
  }
  return out;
}

int show_skills(const CommonOptions& common, double timeout_s) {
  dds::Participant participant(common.domain);
  dds::Reader<rigger_skill_ExecutorAnnouncement> ann(participant, protocol::skill::kExecutors, dds::qos::state());
  dds::EventLoop loop(participant);
  if (!ann.wait_for_writers(1, from_seconds(timeout_s))) {
    std::fprintf(stderr, "riggerctl: no executor on %s\n", dds::describe_domain(common.domain).c_str());
    return kExitFailed;
  }
  // Executors on other hosts, or started just before, may be a discovery round behind the first.
  wait_for_quiet_matching(ann.handle(), DDS_SUBSCRIPTION_MATCHED_STATUS, [&] { return ann.matched_writers(); },
                               std::chrono::milliseconds(600), from_seconds(timeout_s));
  // The announcements are transient-local but arrive after the match; each executor has one writer, so
  // wait until every matched writer's announcement is here.
  std::map<dds_instance_handle_t, std::string> by_writer;  // publication handle → printed text
  std::map<std::string, std::string> shown;                // executor id → printed text (sorted output)
  loop.on_data(ann, [&] {
    ann.take([&](const rigger_skill_ExecutorAnnouncement& a, const dds_sample_info_t& info) {
      if (info.instance_state != DDS_IST_ALIVE) return;
      by_writer[info.publication_handle] = dds::to_string(a.executor_id);
      shown[dds::to_string(a.executor_id)] = describe_executor(a);
    });
  });
  loop.run_until([&] { return by_writer.size() >= static_cast<std::size_t>(ann.matched_writers()); },
                 from_seconds(timeout_s));
  for (const auto& [id, text] : shown) std::fputs(text.c_str(), stdout);
  if (shown.empty()) std::printf("no live executor\n");
  return 0;
}
// --- cancel, pause, resume ---

/// Writes one TaskCommand, issued by riggerctl:$USER.
void send_task_command(dds::Writer<rigger_task_TaskCommand>& commands, const std::string& task_id,
                       rigger_task_TaskCommandKind kind, const std::string& reason) {
  rigger_task_TaskCommand c{};
  const std::string issuer = riggerctl_source();
  c.task_id = dds::wire_string(task_id);
  c.kind = kind;
  c.reason = dds::wire_string(reason);
  c.issuer = dds::wire_string(issuer);
  c.seq = 1;
  c.stamp = dds::wire_now();
  commands.write(c);
}

/// RESUME of an INTERRUPTED task (the controller restarted while it ran): the controller rebuilds it from
/// its journal and asks the operator (prompt kind "resume"). Prints what was done and what will run, and
/// the prompt to answer; exit 0 when the controller waits for the confirmation, 1 when it refused.
int resume_interrupted(dds::Writer<rigger_task_TaskCommand>& commands, dds::Reader<rigger_task_TaskStatus>& statuses,
                       dds::EventLoop& loop, const std::string& task_id, const std::string& reason, double timeout_s) {
  bool sent = false, done = false, before = false;
  std::string code, message;
  loop.on_data(statuses, [&] {
    statuses.take([&](const rigger_task_TaskStatus& s, const dds_sample_info_t&) {
      if (dds::to_string(s.task_id) != task_id) return;
      before = true;
      if (!sent) return;
      const std::string c = dds::to_string(s.code);
      if (c != "RESUME_CONFIRMATION" && c != "RESUME_REFUSED") return;  // the state from before the command
      done = true;
      code = c;
      message = dds::to_string(s.message);
    });
  });
  // The task's status from before (INTERRUPTED, or an earlier resume's answer) is not this one's answer.
  loop.run_until([&] { return before; }, std::chrono::milliseconds(1000));
  sent = true;
  send_task_command(commands, task_id, rigger_task_TASK_RESUME, reason);
  if (!loop.run_until([&] { return done; }, from_seconds(timeout_s))) {
    std::fprintf(stderr, "riggerctl: the task controller did not answer the resume of task %s within %.1f s\n",
                 task_id.c_str(), timeout_s);
    return kExitFailed;
  }
  if (code == "RESUME_REFUSED") {
    std::fprintf(stderr, "riggerctl: task %s cannot be resumed: %s\n", task_id.c_str(), message.c_str());
    return kExitFailed;
  }
  std::printf("task %s was INTERRUPTED (the task controller restarted while it ran)\n%s\n", task_id.c_str(),
              message.c_str());
  std::printf("nothing runs until the operator confirms: answer the prompt kind resume in `riggerctl operator`\n");
  return 0;
}

/// Sends CANCEL, PAUSE or RESUME for `task_id` and waits for the controller's acknowledgement on
/// rigger/task/status: the task's end for CANCEL, PAUSED for PAUSE, RUNNING for RESUME (or the task's
/// end, whichever comes first). Exit 0 when the wanted state was reached.
int task_command(const CommonOptions& common, const std::string& task_id, rigger_task_TaskCommandKind kind,
                 const std::string& reason, double timeout_s) {
  dds::Participant participant(common.domain);
  dds::Writer<rigger_task_TaskCommand> commands(participant, protocol::task::kCommand);
  dds::Reader<rigger_task_TaskStatus> statuses(participant, protocol::task::kStatus);
  JournalTopics topics(participant);
  dds::EventLoop loop(participant);
  if (!commands.wait_for_readers(1, from_seconds(timeout_s))) {
    std::fprintf(stderr, "riggerctl: no task controller on %s\n", dds::describe_domain(common.domain).c_str());
    return kExitNoController;
  }
  // The journal knows whether the task exists and whether it already ended (its last line is the
  // TASK result): the controller ignores commands for such tasks, so there is nothing to wait for.
  const JournalAnswer journal = ask_journal(topics, loop, task_id, timeout_s);
  if (const int failed = journal_failure(journal, common, timeout_s, "no task " + task_id)) return failed;
  // The last TASK line is the task's state: a resumed task has INTERRUPTED, then RUNNING, then its end.
  const JournalLine* task_line = nullptr;
  for (const auto& l : journal.lines)
    if (l.kind == "TASK") task_line = &l;
  if (task_line != nullptr && task_line->code == "INTERRUPTED" && kind == rigger_task_TASK_RESUME)
    return resume_interrupted(commands, statuses, loop, task_id, reason, timeout_s);
  if (task_line != nullptr && task_line->code != "RUNNING") {
    std::printf("task %s had already ended: %s\n", task_id.c_str(), task_line->code.c_str());
    return kind == rigger_task_TASK_CANCEL && task_line->code == "CANCELED" ? 0 : kExitFailed;
  }
  const int wanted = kind == rigger_task_TASK_CANCEL  ? rigger_task_TASK_CANCELED
                     : kind == rigger_task_TASK_PAUSE ? rigger_task_TASK_PAUSED
                                                      : rigger_task_TASK_RUNNING;
  bool sent = false, done = false;
  int state = -1, before = -1;
  // PAUSE / RESUME: what each leaf did. Each executor answers PAUSED (RESUMED), with a code when the
  // leaf runs on; which leaves were asked, the journal says (below).
  const bool leaves = kind != rigger_task_TASK_CANCEL;
  const auto leaf_answer = kind == rigger_task_TASK_PAUSE ? rigger_skill_SKILL_EVENT_PAUSED : rigger_skill_SKILL_EVENT_RESUMED;
  dds::Reader<rigger_skill_SkillEvent> leaf_answers(participant, protocol::skill::kEvent);
  std::map<std::string, std::string> answered;  // by node id: what its executor answered
  if (leaves) {
    loop.on_data(leaf_answers, [&] {
      leaf_answers.take([&](const rigger_skill_SkillEvent& e, const dds_sample_info_t&) {
        if (!sent || e.kind != leaf_answer || dds::to_string(e.task_id) != task_id) return;
        const std::string code = dds::to_string(e.code);
        answered[dds::to_string(e.node_id)] = (code.empty() ? "" : code + ": ") + dds::to_string(e.message);
      });
    });
  }
  loop.on_data(statuses, [&] {
    statuses.take([&](const rigger_task_TaskStatus& s, const dds_sample_info_t&) {
      if (dds::to_string(s.task_id) != task_id) return;
      if (!sent) before = s.state;
      if (task_terminal(s.state) || (sent && s.state == wanted)) {
        done = true;
        state = s.state;
      }
    });
  });
  // The task's current state (transient-local) first, so that a state from before the command is
  // not taken for its acknowledgement.
  loop.run_until([&] { return before >= 0; }, std::chrono::milliseconds(1000));
  if (done) {
    std::printf("task %s had already ended: %s\n", task_id.c_str(), task_state_name(state));
    return state == wanted ? 0 : kExitFailed;
  }
  if (before == wanted && kind == rigger_task_TASK_RESUME) {
    std::fprintf(stderr, "riggerctl: task %s is RUNNING, neither PAUSED nor INTERRUPTED: nothing to resume\n",
                 task_id.c_str());
    return kExitFailed;
  }
  if (before == wanted) {
    std::printf("task %s is %s already\n", task_id.c_str(), task_state_name(before));
    return 0;
  }
  sent = true;
  send_task_command(commands, task_id, kind, reason);
  if (!loop.run_until([&] { return done; }, from_seconds(timeout_s))) {
    std::fprintf(stderr, "riggerctl: task %s was not %s within %.1f s\n", task_id.c_str(), task_state_name(wanted),
                 timeout_s);
    return kExitFailed;
  }
  std::printf("task %s %s\n", task_id.c_str(), task_state_name(state));
  if (leaves && state == wanted) {
    // The controller journals a COMMAND row per leaf it sends the command to, in the same turn as the
    // acknowledgement, and each answer as an EVENT row (PAUSED, or NOT_PAUSED with the code). The leaves
    // asked this time are the rows after the last task-level one. Answers come live on
    // rigger/skill/event, or from the journal when this reader had not yet matched an executor's writer.
    const std::string command = kind == rigger_task_TASK_PAUSE ? "PAUSE" : "RESUME";
    const std::string answer = kind == rigger_task_TASK_PAUSE ? "PAUSED" : "RESUMED";
    std::vector<std::string> asked;
    std::uint64_t request = 2;
    const auto read_journal = [&] {
      std::map<std::string, std::string> journaled;  // this command's answers only
      asked.clear();
      for (const auto& l : ask_journal(topics, loop, task_id, timeout_s, request++).lines) {
        if (l.kind == "COMMAND" && l.code == command && l.node_id.empty()) {
          asked.clear();
          journaled.clear();
        } else if (l.kind == "COMMAND" && l.code == command) {
          asked.push_back(l.node_id);
        } else if (l.kind == "EVENT" && (l.code == answer || l.code == "NOT_" + answer)) {
          journaled[l.node_id] = l.message;
        }
      }
      answered.insert(journaled.begin(), journaled.end());
    };
    const auto all_answered = [&] {
      return std::all_of(asked.begin(), asked.end(), [&](const std::string& n) { return answered.count(n) > 0; });
    };
    const auto deadline = std::chrono::steady_clock::now() + from_seconds(timeout_s);
    read_journal();
    while (!all_answered() && std::chrono::steady_clock::now() < deadline) {
      loop.run_until(all_answered, std::chrono::milliseconds(300));  // woken by a live answer
      if (!all_answered()) read_journal();
    }
    for (const auto& node : asked) {
      const auto a = answered.find(node);
      std::printf("  %s: %s\n", node.c_str(), a == answered.end() ? "no answer" : a->second.c_str());
    }
  }
  if (kind == rigger_task_TASK_PAUSE && state == wanted)
    std::printf("no new leaf starts until `riggerctl resume %s`; running leaves of pausable skills hold still, "
                "those that cannot pause run on (monitors, operator prompts) or, holding a device, are brought to "
                "their safe stop\n",
                task_id.c_str());
  return state == wanted ? 0 : kExitFailed;
}

}  // namespace

void add_task_commands(CLI::App& app, const CommonOptions& common, int& exit_code) {
  {
    auto* cmd = app.add_subcommand("validate", "Validate a recipe offline against a skill-library file (exit 0/1).");
    auto file = std::make_shared<std::string>();
    auto library =
        std::make_shared<std::string>(find_data_path("recipes/examples/skill_library.json").path.string());
    cmd->add_option("FILE", *file, "recipe file")->required();
    cmd->add_option("--library", *library,
                    "skill-library file (default: recipes/examples/skill_library.json of the installation)");
    cmd->callback([file, library, &exit_code] { exit_code = validate(*file, *library); });
  }
  {
    auto* cmd = app.add_subcommand("run", "Submit a recipe, show the live tree, exit 0 on SUCCEEDED.");
    auto opt = std::make_shared<RunOptions>();
    cmd->add_option("FILE", opt->file, "recipe file")->required();
    cmd->add_option("--task-id", opt->task_id, "submit under this task id (re-running a file needs a new id)");
    cmd->add_option("--timeout", opt->timeout_s, "give up waiting after S seconds (0: never)");
    cmd->add_option("--match-timeout", opt->match_timeout_s, "wait this long for the task controller");
    cmd->add_flag("--quiet", opt->quiet, "print only task state changes");
    cmd->callback([opt, &common, &exit_code] { exit_code = run_recipe(common, *opt); });
  }
  auto timeout = std::make_shared<double>(5.0);
  {
    auto* cmd = app.add_subcommand("status", "List the tasks the controller's journal knows, newest first.");
    cmd->add_option("--timeout", *timeout, "seconds to wait for the controller");
    cmd->callback([timeout, &common, &exit_code] { exit_code = journal_query(common, "", *timeout); });
  }
  {
    auto* cmd = app.add_subcommand("log", "The journal's timeline of a task.");
    auto task = std::make_shared<std::string>();
    cmd->add_option("TASK", *task, "task id")->required();
    cmd->add_option("--timeout", *timeout, "seconds to wait for the controller");
    cmd->callback([task, timeout, &common, &exit_code] { exit_code = journal_query(common, *task, *timeout); });
  }
  {
    auto* cmd = app.add_subcommand("tree", "The last status of every node of a task.");
    auto task = std::make_shared<std::string>();
    cmd->add_option("TASK", *task, "task id")->required();
    cmd->add_option("--timeout", *timeout, "seconds to wait for the controller");
    cmd->callback([task, timeout, &common, &exit_code] { exit_code = show_tree(common, *task, *timeout); });
  }
  {
    auto* cmd = app.add_subcommand("skills", "Live executors and the skills and monitors they offer.");
    cmd->add_option("--timeout", *timeout, "seconds to wait for an executor");
    cmd->callback([timeout, &common, &exit_code] { exit_code = show_skills(common, *timeout); });
  }
  {
    auto* cmd = app.add_subcommand("cancel", "Cancel a running task and wait until it stopped.");
    auto task = std::make_shared<std::string>();
    auto reason = std::make_shared<std::string>("canceled from riggerctl");
    cmd->add_option("TASK", *task, "task id")->required();
    cmd->add_option("--reason", *reason, "why (journalled)");
    cmd->add_option("--timeout", *timeout, "seconds to wait for the task to end");
    cmd->callback([task, reason, timeout, &common, &exit_code] {
      exit_code = task_command(common, *task, rigger_task_TASK_CANCEL, *reason, *timeout);
    });
  }
  for (const auto& [verb, kind, help] :
       {std::tuple<const char*, rigger_task_TaskCommandKind, const char*>{
            "pause", rigger_task_TASK_PAUSE, "Pause a running task (no new leaf starts) and wait until it is PAUSED."},
        {"resume", rigger_task_TASK_RESUME,
         "Resume a paused task and wait until it is RUNNING again; or an INTERRUPTED task (the controller "
         "restarted while it ran): print what was done and what will run, which starts once the operator "
         "confirms."}}) {
    auto* cmd = app.add_subcommand(verb, help);
    auto task = std::make_shared<std::string>();
    auto reason = std::make_shared<std::string>(std::string(verb) + "d from riggerctl");
    auto wait_s = std::make_shared<double>(10.0);
    cmd->add_option("TASK", *task, "task id")->required();
    cmd->add_option("--reason", *reason, "why (journalled)");
    cmd->add_option("--timeout", *wait_s, "seconds to wait for the acknowledgement");
    const auto k = kind;
    cmd->callback([task, reason, wait_s, k, &common, &exit_code] {
      exit_code = task_command(common, *task, k, *reason, *wait_s);
    });
  }
}

}  // namespace rigger::ctl
