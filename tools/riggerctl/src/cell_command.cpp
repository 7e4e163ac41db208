// `riggerctl cell …`: the cell's revisions, kept by the world model (rigger/world/cell_request, answered on
// rigger/world/cell_reply; docs/world-model.md "Cell revisions").
#include <unistd.h>

#include <cstdio>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "commands.hpp"
#include "rigger/base/bounded_json.hpp"
#include "rigger/base/sha256.hpp"
#include "rigger/base/text.hpp"
#include "rigger/base/time.hpp"
#include "rigger/cell_config/cell_diff.hpp"
#include "rigger/cell_config/cell_models.hpp"
#include "rigger/dds/event_loop.hpp"
#include "rigger/dds/pubsub.hpp"
#include "rigger/protocol/world.hpp"
#include "rigger/world_protocol/cell_protocol.hpp"

namespace rigger::ctl {
namespace {

using json = nlohmann::json;
using world_protocol::CellOp;
using world_protocol::CellReply;
using world_protocol::CellRequest;

constexpr int kExitRefused = 1;
constexpr int kExitUsage = 2;
constexpr int kExitNoWorldModel = 3;

struct CellOptions {
  CellOp op = CellOp::kHistory;
  std::string file;
  std::string comment;
  bool dry_run = false;
  bool with_models = false;
  bool as_json = false;
  std::uint64_t revision = 0;
  std::uint64_t other = 0;  // diff: the second revision
  double timeout_s = 10;
};

// A conversation with the world model: waits for it, then asks. Reads (show, history) are asked again
// until answered: the world model may answer before its reply writer has discovered this process.
class CellSession {
 public:
  explicit CellSession(const CommonOptions& common)
      : domain_(common.domain),
        participant_(common.domain),
        loop_(participant_),
        requests_(participant_, protocol::world::kCellRequest),
        replies_(participant_, protocol::world::kCellReply) {
    loop_.on_data(replies_, [this] {
      replies_.take([this](const rigger_world_CellReply& wire, const dds_sample_info_t&) {
        CellReply r = world_protocol::from_wire(wire);
        if (r.client_id == client_id_ && r.request_id == next_id_ - 1) answer_ = std::move(r);
      });
    });
  }

  bool connect(double timeout_s) {
    const auto timeout = from_seconds(timeout_s);
    return requests_.wait_for_readers(1, timeout) && replies_.wait_for_writers(1, timeout);
  }

  /// The answer, or nullopt (printed) after the timeout.
  std::optional<CellReply> ask(CellRequest request, double timeout_s, bool resend) {
    request.client_id = client_id_;
    request.request_id = next_id_++;
    request.who = riggerctl_source();
    answer_.reset();
    const auto deadline = std::chrono::steady_clock::now() + from_seconds(timeout_s);
    do {
      rigger_world_CellRequest wire{};
      std::vector<rigger_world_CellModel> models;
      world_protocol::to_wire(request, wire, models);
      if (const dds_return_t rc = requests_.write(wire); rc != DDS_RETCODE_OK) {
        std::fprintf(stderr, "riggerctl cell: sending the request failed: %s\n", dds_strretcode(rc));
        return std::nullopt;
      }
      const auto wait = resend ? std::min<std::chrono::nanoseconds>(std::chrono::milliseconds(500),
                                                                    deadline - std::chrono::steady_clock::now())
                               : std::chrono::nanoseconds(deadline - std::chrono::steady_clock::now());
      if (loop_.run_until([&] { return answer_.has_value(); }, wait)) return answer_;
    } while (resend && std::chrono::steady_clock::now() < deadline);
    std::fprintf(stderr, "riggerctl cell: the world model did not answer within %.1f s\n", timeout_s);
    return std::nullopt;
  }

  std::uint32_t domain() const { return domain_; }

 private:
  std::uint32_t domain_;
  dds::Participant participant_;
  dds::EventLoop loop_;
  dds::Writer<rigger_world_CellRequest> requests_;
  dds::Reader<rigger_world_CellReply> replies_;
  std::string client_id_ = "riggerctl-" + std::to_string(::getpid());
  std::uint64_t next_id_ = 1;
  std::optional<CellReply> answer_;
};

std::string time_text(std::int64_t unix_ns) {
  const std::time_t t = static_cast<std::time_t>(unix_ns / 1'000'000'000);
  std::tm tm{};
  gmtime_r(&t, &tm);
  char text[32];
  std::strftime(text, sizeof text, "%Y-%m-%dT%H:%M:%SZ", &tm);
  return text;
}

std::string join(const json& items) {
  std::string text;
  for (const json& item : items) text += (text.empty() ? "" : ", ") + item.get<std::string>();
  return text;
}

// One line per entity: "+ id" added, "- id" removed, "~ id moved ..." moved, "* id changed: keys".
void print_changes(const json& changes) {
  for (const json& id : changes.value("added", json::array()))
    std::printf("+ %s added\n", id.get<std::string>().c_str());
  for (const json& id : changes.value("removed", json::array()))
    std::printf("- %s removed\n", id.get<std::string>().c_str());
  for (const json& m : changes.value("moved", json::array())) {
    std::string parent;
    if (m.value("parent_before", "") != m.value("parent_after", ""))
      parent = " (parent " + m.value("parent_before", "") + " -> " + m.value("parent_after", "") + ")";
    std::printf("~ %s moved %s m, %s deg%s\n", m.at("id").get<std::string>().c_str(),
                number_text(m.value("distance_m", 0.0)).c_str(), number_text(m.value("angle_deg", 0.0)).c_str(),
                parent.c_str());
  }
  for (const json& c : changes.value("changed", json::array()))
    std::printf("* %s changed: %s\n", c.at("id").get<std::string>().c_str(), join(c.at("keys")).c_str());
}

json result_of(const CellReply& reply) {
  if (reply.result_json.empty()) return json::object();
  try {
    return json::parse(reply.result_json);
  } catch (const json::exception&) {
    return json::object();
  }
}

int refused(const char* what, const CellReply& reply) {
  std::fprintf(stderr, "riggerctl cell %s: %s: %s\n", what, reply.code.c_str(), reply.message.c_str());
  return kExitRefused;
}

// --with-models: the STEP model of every object that is new or whose model changed against `running` (the
// running revision's document) goes with the request, pinned by its sha256 (a pin the file has must match
// the bytes), so that a world model and services without those files can run the revision. Objects whose
// model is as running are left as they are: their pins (or their absence) do not change.
// "" or what is wrong, naming the file and the JSON pointer.
std::string attach_models(const std::string& file, CellRequest& request, const json& running) {
  std::map<std::string, json> running_models;
  for (const json& e : running.value("entities", json::array()))
    if (e.is_object() && e.value("id", json()).is_string() && e.contains("model"))
      running_models[e["id"].get<std::string>()] = e["model"];
  const JsonParseResult parsed = parse_json_bounded(request.cell_json, {cell::kMaxCellFileBytes, cell::kMaxCellFileDepth});
  if (!parsed.ok()) return file + ": " + parsed.error->to_string();
  json doc = parsed.value;
  if (!doc.is_object() || !doc.value("entities", json()).is_array()) return file + ": /entities: expected an array";
  const std::filesystem::path folder = cell::cell_model_folder(file);
  bool pinned = false;
  json& entities = doc["entities"];
  for (std::size_t i = 0; i < entities.size(); ++i) {
    json* model = entities[i].is_object() && entities[i].contains("model") ? &entities[i]["model"] : nullptr;
    if (model == nullptr || !model->is_object() || !model->value("step", json()).is_string()) continue;
    const auto as_running = running_models.find(entities[i].value("id", ""));
    if (as_running != running_models.end() && as_running->second == *model) continue;
    const std::string pointer = "/entities/" + std::to_string(i) + "/model";
    const std::string name = model->at("step");
    if (const std::string problem = cell::model_name_problem(name); !problem.empty())
      return file + ": " + pointer + "/step: " + problem;
    std::ifstream in(folder / name, std::ios::binary);
    std::string bytes;
    if (in) bytes.assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
    if (!in.eof() && !in) return file + ": " + pointer + "/step: " + (folder / name).string() + ": cannot read it";
    if (bytes.size() > cell::kMaxModelBytes)
      return file + ": " + pointer + "/step: " + (folder / name).string() + ": larger than 64 MiB";
    const std::string sha256 = sha256_hex(bytes);
    if (model->contains("sha256") && model->at("sha256") != sha256) {
      return file + ": " + pointer + "/sha256: pins " + model->at("sha256").dump() + ", but " +
             (folder / name).string() + " has " + sha256;
    }
    if (!model->contains("sha256")) {
      (*model)["sha256"] = sha256;
      pinned = true;
    }
    bool sent = false;
    for (const world_protocol::CellModel& m : request.models) sent = sent || m.sha256 == sha256;
    if (!sent) request.models.push_back({sha256, name, std::move(bytes)});
  }
  if (request.models.size() > cell::kMaxModelsPerRequest)
    return file + ": names " + std::to_string(request.models.size()) + " STEP models, at most 16 go with a request";
  if (pinned) request.cell_json = doc.dump(2) + "\n";
  return {};
}

int propose(CellSession& session, const CellOptions& o) {
  CellRequest request;
  request.op = o.op;
  request.dry_run = o.dry_run;
  request.comment = o.comment;
  request.revision = o.revision;
  const char* what = o.op == CellOp::kApply ? "apply" : "rollback";
  if (o.op == CellOp::kApply) {
    std::ifstream in(o.file, std::ios::binary);
    if (!in) {
      std::fprintf(stderr, "riggerctl cell apply: %s: cannot read the file\n", o.file.c_str());
      return kExitUsage;
    }
    request.cell_json.assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
  }
  // A read first, asked until answered: then the world model's reply writer knows this process, and the
  // proposal (sent once: it is not a read) cannot be answered into the void. With --with-models, the read
  // is the running revision, against which the models to send are chosen.
  CellRequest hello;
  hello.op = o.with_models && o.op == CellOp::kApply ? CellOp::kShow : CellOp::kHistory;
  const std::optional<CellReply> answered = session.ask(hello, o.timeout_s, true);
  if (!answered) return kExitNoWorldModel;
  if (o.with_models && o.op == CellOp::kApply) {
    const json shown = result_of(*answered);
    const JsonParseResult running =
        parse_json_bounded(shown.value("cell_json", "{}"), {cell::kMaxCellFileBytes, cell::kMaxCellFileDepth});
    if (const std::string problem = attach_models(o.file, request, running.ok() ? running.value : json::object());
        !problem.empty()) {
      std::fprintf(stderr, "riggerctl cell apply: %s\n", problem.c_str());
      return kExitUsage;
    }
  }
  const std::optional<CellReply> reply = session.ask(request, o.timeout_s, false);
  if (!reply) return kExitRefused;
  if (!reply->ok) return refused(what, *reply);
  const json result = result_of(*reply);
  if (o.as_json) {
    std::printf("%s\n", result.dump(2).c_str());
    return 0;
  }
  if (o.dry_run) {
    std::printf("dry run: nothing changed; %s (running revision %llu)\n", reply->message.c_str(),
                static_cast<unsigned long long>(reply->cell_revision));
  } else {
    std::printf("cell revision %llu (previous %llu): %s\n", static_cast<unsigned long long>(reply->cell_revision),
                static_cast<unsigned long long>(result.value("previous_revision", 0ULL)),
                result.value("summary", "").c_str());
  }
  print_changes(result.value("changes", json::object()));
  return 0;
}

std::optional<json> show(CellSession& session, std::uint64_t revision, double timeout_s, int& code) {
  CellRequest request;
  request.op = CellOp::kShow;
  request.revision = revision;
  const std::optional<CellReply> reply = session.ask(request, timeout_s, true);
  if (!reply) {
    code = kExitNoWorldModel;
    return std::nullopt;
  }
  if (!reply->ok) {
    code = refused("show", *reply);
    return std::nullopt;
  }
  return result_of(*reply);
}

int diff(CellSession& session, const CellOptions& o) {
  int code = 0;
  const std::optional<json> a = show(session, o.revision, o.timeout_s, code);
  if (!a) return code;
  const std::optional<json> b = show(session, o.other, o.timeout_s, code);
  if (!b) return code;
  try {
    const std::string name_a = "revision " + std::to_string(o.revision), name_b = "revision " + std::to_string(o.other);
    const std::string text_a = a->at("cell_json"), text_b = b->at("cell_json");
    const cell::CellFile cell_a = cell::parse_cell_file(text_a, name_a), cell_b = cell::parse_cell_file(text_b, name_b);
    const json changes = cell::diff_cells(cell_a, json::parse(text_a), cell_b, json::parse(text_b));
    if (o.as_json) {
      std::printf("%s\n", changes.dump(2).c_str());
    } else {
      std::printf("revision %llu -> %llu: %s\n", static_cast<unsigned long long>(o.revision),
                  static_cast<unsigned long long>(o.other), cell::summarize_changes(changes).c_str());
      print_changes(changes);
    }
  } catch (const std::exception& e) {
    std::fprintf(stderr, "riggerctl cell diff: %s\n", e.what());
    return kExitRefused;
  }
  return 0;
}

int history(CellSession& session, const CellOptions& o) {
  CellRequest request;
  request.op = CellOp::kHistory;
  const std::optional<CellReply> reply = session.ask(request, o.timeout_s, true);
  if (!reply) return kExitNoWorldModel;
  if (!reply->ok) return refused("history", *reply);
  const json result = result_of(*reply);
  if (o.as_json) {
    std::printf("%s\n", result.dump(2).c_str());
    return 0;
  }
  std::printf("  %-5s %-20s %-24s %-12s %-28s %s\n", "REV", "WHEN (UTC)", "WHO", "SHA256", "CHANGES", "COMMENT");
  for (const json& r : result.value("revisions", json::array())) {
    const std::uint64_t rev = r.value("cell_revision", 0ULL);
    std::printf("%s %-5llu %-20s %-24s %-12s %-28s %s\n", rev == result.value("running", 0ULL) ? "*" : " ",
                static_cast<unsigned long long>(rev), time_text(r.value("stamp_ns", 0LL)).c_str(),
                r.value("who", "").c_str(), r.value("sha256", "").substr(0, 12).c_str(), r.value("summary", "").c_str(),
                r.value("comment", "").c_str());
  }
  return 0;
}

int run(const CommonOptions& common, const CellOptions& o) {
  CellSession session(common);
  if (!session.connect(o.timeout_s)) {
    std::fprintf(stderr, "riggerctl cell: no world model on %s (waited %.1f s)\n",
                 dds::describe_domain(common.domain).c_str(), o.timeout_s);
    return kExitNoWorldModel;
  }
  switch (o.op) {
    case CellOp::kApply:
    case CellOp::kRollback:
      return propose(session, o);
    case CellOp::kShow: {
      if (o.other != 0) return diff(session, o);
      int code = 0;
      const std::optional<json> shown = show(session, o.revision, o.timeout_s, code);
      if (!shown) return code;
      if (o.as_json) {
        json copy = *shown;
        copy["cell"] = json::parse(copy.value("cell_json", "{}"));
        copy.erase("cell_json");
        std::printf("%s\n", copy.dump(2).c_str());
      } else {
        const std::string text = shown->value("cell_json", "");
        std::fwrite(text.data(), 1, text.size(), stdout);
        if (!text.empty() && text.back() != '\n') std::fputc('\n', stdout);
      }
      return 0;
    }
    case CellOp::kHistory:
      return history(session, o);
  }
  return kExitUsage;
}

}  // namespace

void add_cell_command(CLI::App& app, const CommonOptions& common, int& exit_code) {
  auto o = std::make_shared<CellOptions>();
  auto* cell = app.add_subcommand("cell", "The cell's revisions, kept by the world model");
  cell->require_subcommand(1);
  cell->add_option("--timeout", o->timeout_s, "Seconds to wait for the world model and its answer (default 10)");
  cell->add_flag("--json", o->as_json, "Print the world model's answer as JSON");
  auto* apply = cell->add_subcommand("apply", "Propose FILE as the next revision (validated like a start)");
  apply->add_option("file", o->file, "the cell file")->required();
  apply->add_option("--comment", o->comment, "Why (kept in the history)");
  apply->add_flag("--dry-run", o->dry_run, "Validate and show what would change; change nothing");
  apply->add_flag("--with-models", o->with_models,
                  "Send the STEP models FILE names with it, each pinned by its sha256 (for a world model and services "
                  "whose cell folder lacks them)");
  apply->callback([o] { o->op = CellOp::kApply; });
  auto* show = cell->add_subcommand("show", "Print a revision's document (default: the running one)");
  show->add_option("revision", o->revision, "the revision");
  show->callback([o] { o->op = CellOp::kShow; });
  auto* history = cell->add_subcommand("history", "List the kept revisions (* marks the running one)");
  history->callback([o] { o->op = CellOp::kHistory; });
  auto* diff = cell->add_subcommand("diff", "What revision B changes against revision A, object by object");
  diff->add_option("a", o->revision, "revision A")->required()->check(CLI::PositiveNumber);
  diff->add_option("b", o->other, "revision B")->required()->check(CLI::PositiveNumber);
  diff->callback([o] { o->op = CellOp::kShow; });
  auto* rollback = cell->add_subcommand("rollback", "Bring revision REV back, as a new revision");
  rollback->add_option("revision", o->revision, "the revision")->required()->check(CLI::PositiveNumber);
  rollback->add_option("--comment", o->comment, "Why (default: \"rollback to revision REV\")");
  rollback->add_flag("--dry-run", o->dry_run, "Validate and show what would change; change nothing");
  rollback->callback([o] { o->op = CellOp::kRollback; });
  for (CLI::App* sub : {apply, show, history, diff, rollback}) sub->fallthrough();  // --json, --timeout after it
  cell->callback([&common, &exit_code, o] { exit_code = run(common, *o); });
}

}  // namespace rigger::ctl
