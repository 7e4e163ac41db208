#include "console_node.hpp"

#include <algorithm>
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <optional>

#include "rigger/base/bounded_json.hpp"
#include "rigger/cell_config/cell_file.hpp"
#include "rigger/console/settings.hpp"
#include "rigger/dds/conversions.hpp"
#include "rigger/dds/sequences.hpp"

#include "rigger/operator_protocol/prompt.hpp"

namespace rigger::console {

using nlohmann::json;

namespace {

constexpr std::size_t kEventCapacity = 200000;
constexpr std::size_t kPlotCapacity = 36000;  // 30 min at 20 Hz
// The 3D cell's changes: smooth enough to follow a moving load by eye, few enough for the event log
// (200000 events hold 5.5 h of them) and a page on a slow link.
constexpr double kCellRateHz = 10.0;

double seconds(const rigger_geometry_Time& t) { return static_cast<double>(t.sec) + 1e-9 * t.nanosec; }

double wall_now_s() {
  return std::chrono::duration<double>(std::chrono::system_clock::now().time_since_epoch()).count();
}

std::string epoch_now() {
  const auto ms = std::chrono::duration_cast<std::chrono::milliseconds>(std::chrono::system_clock::now().time_since_epoch());
  return std::to_string(ms.count());
}

// A plot value with 4 significant decimals keeps the rows short.
double round4(double v) { return std::round(v * 1e4) / 1e4; }

}  // namespace

ConsoleNode::ConsoleNode(service::ServiceContext& ctx)
    : ctx_(ctx),
      events_(kEventCapacity, epoch_now()),
      plots_(kPlotCapacity, events_.epoch()),
      state_(events_),
      tasks_(ctx.participant, state_, skills_),
      prompts_(ctx.participant, protocol::operator_ui::kPrompt),
      wrench_(ctx.participant, protocol::robot::kWrench),
      crane_(ctx.participant, protocol::crane::kState),
      robot_(ctx.participant, protocol::robot::kState),
      admittance_(ctx.participant, protocol::admittance::kState),
      entities_(ctx.participant, protocol::world::kEntity),
      cell_requests_(ctx.participant, protocol::world::kCellRequest),
      cell_replies_(ctx.participant, protocol::world::kCellReply),
      cell_revisions_(ctx.participant, protocol::world::kCell),
      cell_models_(ctx.participant, protocol::world::kCellModel),
      recipes_(ctx.participant, protocol::task::kRecipe),
      task_commands_(ctx.participant, protocol::task::kCommand),
      responses_(ctx.participant, protocol::operator_ui::kResponse),
      journal_queries_(ctx.participant, protocol::task::kJournalQuery),
      journal_replies_(ctx.participant, protocol::task::kJournalReply),
      cad_requests_(ctx.participant, protocol::cad::kRequest),
      cad_replies_(ctx.participant, protocol::cad::kReply),
      client_id_(ctx.options.id + "-" + std::to_string(::getpid())) {
  const ConsoleSettings settings = read_console_settings(ctx.config);
  HttpConfig http;
  http.config_file = ctx.options.config_path;
  http.address = settings.address;
  http.port = settings.port;
  http.web_dir = settings.web_dir;
  http.audit_log = settings.audit_log;
  http.tls_cert = settings.tls_cert;
  http.tls_key = settings.tls_key;
  http.confirm_timeout = settings.confirm_timeout;
  http.max_body_bytes = settings.max_body_bytes;
  http.max_streams = settings.max_streams;
  http.max_import_bytes = settings.max_import_bytes;
  query_timeout_ = settings.query_timeout;
  const std::optional<std::uint32_t> rehearsal_domain = settings.rehearsal_domain;
  if (rehearsal_domain && *rehearsal_domain == ctx.participant.domain_id())
    throw ConfigError(ctx.options.config_path, "/rehearsal_domain",
                      "the rehearsal domain must not be the cell's own domain " + std::to_string(*rehearsal_domain) +
                          ": a rehearsal would run on the real cell");
  if (!http.audit_log.empty()) {
    const auto slash = http.audit_log.rfind('/');
    if (slash != std::string::npos && slash > 0) std::filesystem::create_directories(http.audit_log.substr(0, slash));
  }
  Users users = Users::load(settings.users_file);
  if (!settings.runs_dir.empty()) {
    try {
      runs_ = std::make_unique<RunArchive>(settings.runs_dir, RunArchive::Limits{settings.max_runs});
    } catch (const std::runtime_error& e) {
      throw ConfigError(ctx.options.config_path, "/runs_dir", e.what());
    }
    tasks_.on_task_status([this](const std::string& task, const std::string& state, double stamp) {
      runs_->on_task(task, state, stamp);
    });
  }

  world_ = std::make_unique<world_client::WorldClient>(ctx.participant, ctx.loop, ctx.log, client_id_ + "-world");
  tasks_.attach(ctx.loop);
  std::optional<RehearsalFeed> rehearsal_feed;
  if (rehearsal_domain) {
    std::optional<std::pair<LaunchCommand, LaunchTimes>> launch;
    if (!settings.rehearsal_start.empty()) {
      const auto folder = [](const std::filesystem::path& p) { return p.parent_path().string(); };
      std::error_code ec;
      const std::filesystem::path self = std::filesystem::read_symlink("/proc/self/exe", ec);
      launch.emplace(LaunchCommand{settings.rehearsal_start, settings.rehearsal_env,
                                   folder(std::filesystem::absolute(ctx.options.config_path)),
                                   settings.rehearsal_log, ec ? "" : folder(self)},
                     LaunchTimes{settings.rehearsal_start_timeout, settings.rehearsal_idle_stop,
                                 settings.rehearsal_stop_timeout});
      // A folder that cannot be made is said at the first start, which cannot open the log.
      std::filesystem::create_directories(std::filesystem::path(settings.rehearsal_log).parent_path(), ec);
    }
    rehearsal_ = std::make_unique<RehearsalLink>(
        *rehearsal_domain, ctx.loop, events_.epoch(), query_timeout_, std::move(launch),
        [this, domain = *rehearsal_domain](const CellChange& change, const std::string& who) {
          ctx_.log->info("rehearsal_cell domain={} phase={} what={}", domain, phase_name(change.phase), change.what);
          if (http_) http_->audit_system("rehearsal_cell", "domain " + std::to_string(domain), change.what, who);
        },
        settings.rehearsal_cell_folder);
    rehearsal_feed.emplace(rehearsal_->feed());
    ctx.log->info("rehearsal domain={}", *rehearsal_domain);
  }
  ctx.loop.on_data(prompts_, [this] { on_prompts(); });
  ctx.loop.on_data(journal_replies_, [this] { on_journal_replies(); });
  ctx.loop.on_data(cad_replies_, [this] { on_cad_replies(); });
  ctx.loop.on_data(cell_replies_, [this] { on_cell_replies(); });
  ctx.loop.on_data(cell_revisions_, [this] { on_cell_revisions(); });
  ctx.loop.on_data(cell_models_, [this] { on_cell_models(); });
  ctx.loop.on_data(wrench_, [this] {
    wrench_.take([this](const rigger_sensing_WrenchStamped& w, const dds_sample_info_t&) {
      force_sum_ += dds::to_domain(w.wrench.force);
      ++force_count_;
      sampled();
    });
  });
  ctx.loop.on_data(crane_, [this] {
    crane_.take([this](const rigger_crane_CraneState& c, const dds_sample_info_t&) {
      crane_velocity_ = Eigen::Vector3d(c.velocity_mps[0], c.velocity_mps[1], c.velocity_mps[2]);
      have_crane_ = true;
      sampled();
      cell_.hook(dds::to_string(c.header.frame_id), Eigen::Vector3d(c.position_m[0], c.position_m[1], c.position_m[2]));
      cell_moved();
    });
  });
  ctx.loop.on_data(robot_, [this] {
    robot_.take([this](const rigger_robot_RobotState& r, const dds_sample_info_t&) {
      robot_velocity_ = dds::to_domain(r.tool_twist.linear);
      have_robot_ = true;
      sampled();
      cell_.tool(dds::to_string(r.header.frame_id), dds::to_domain(r.tool_pose).translation());
      cell_moved();
    });
  });
  ctx.loop.on_data(admittance_, [this] {
    admittance_.take([this](const rigger_admittance_AdmittanceState& a, const dds_sample_info_t&) {
      servo_error_m_ = a.servo_error_m;
      servo_error_rad_ = a.servo_error_rad;
      have_admittance_ = true;
      sampled();
    });
  });
  ctx.loop.on_data(entities_, [this] {
    entities_.take([this](const rigger_world_EntityState& e, const dds_sample_info_t&) {
      const char* kind = e.kind == rigger_world_ENTITY_OBJECT ? "object" : e.kind == rigger_world_ENTITY_DEVICE ? "device" : "frame";
      cell_.entity(dds::to_string(e.entity_id), kind, dds::to_string(e.parent_frame),
                   e.has_pose ? std::optional(dds::to_domain(e.pose.pose)) : std::nullopt);
      cell_moved();
    });
  });
  plot_period_ = std::chrono::nanoseconds(static_cast<long>(1e9 / settings.plot_rate_hz));

  http_ = std::make_unique<HttpApi>(std::move(http), std::move(users), state_, events_, plots_, *this, skills_, ctx.log,
                                    rehearsal_feed, runs_.get());
  http_->start();
  // The address for people and launchers (rigger-compose prints it with a login link).
  std::printf("console: listening on %s://%s:%d/\n", http_->tls() ? "https" : "http",
              settings.address.c_str(), http_->port());
  std::fflush(stdout);
}

ConsoleNode::~ConsoleNode() {
  http_->stop();  // before the readers and the loop's handlers go away
  rehearsal_.reset();  // its started cell stops now, journaled while the audit log is still there
}

// --- reading ---

void ConsoleNode::on_prompts() {
  prompts_.take([this](const rigger_operator_ui_OperatorPrompt& w, const dds_sample_info_t&) {
    const operator_protocol::Prompt p = operator_protocol::from_wire(w);
    JsonParseResult parsed = parse_json_bounded(p.details_json.empty() ? "{}" : p.details_json, {64U * 1024U, 16});
    json details = parsed.ok() && parsed.value.is_object() ? std::move(parsed.value) : json::object();
    state_.update_prompt({{"prompt_id", p.prompt_id}, {"task_id", p.task_id}, {"node_id", p.node_id},
                          {"kind", p.kind}, {"title", p.title}, {"text", p.text}, {"options", p.options},
                          {"details", details}, {"timeout_s", p.timeout_s}, {"active", p.active},
                          {"stamp", seconds(w.stamp)}});
  });
}

void ConsoleNode::sampled() {
  fresh_ = true;
  if (plot_timer_ != 0) return;
  // The first sample after a quiet spell: ticks again, the interval of the first row's yank starting now.
  last_tick_s_ = wall_now_s();
  plot_timer_ = ctx_.loop.every(plot_period_, [this] { plot_tick(); });
}

void ConsoleNode::plot_tick() {
  const double now = wall_now_s();
  if (!fresh_) {
    // Nothing new: no row, and no more ticks until a sample comes (an idle console does not wake
    // plot_rate_hz times a second for nothing).
    last_tick_s_ = now;
    ctx_.loop.cancel(plot_timer_);
    plot_timer_ = 0;
    return;
  }
  fresh_ = false;
  nlohmann::ordered_json row;  // "t" stays the first key
  row["t"] = std::round(now * 1000.0) / 1000.0;  // first key: /api/plots reads it without parsing
  if (force_count_ > 0) {
    const Eigen::Vector3d f = force_sum_ / force_count_;
    const double norm = f.norm();
    row["fx"] = round4(f.x());
    row["fy"] = round4(f.y());
    row["fz"] = round4(f.z());
    row["f"] = round4(norm);
    if (last_force_norm_ >= 0.0 && now > last_tick_s_) row["yank"] = round4((norm - last_force_norm_) / (now - last_tick_s_));
    last_force_norm_ = norm;
    force_sum_.setZero();
    force_count_ = 0;
  }
  if (have_crane_) {
    row["crane_v"] = round4(crane_velocity_.norm());
    row["crane_vz"] = round4(crane_velocity_.z());
  }
  if (have_robot_) row["robot_v"] = round4(robot_velocity_.norm());
  if (have_admittance_) {
    row["servo_m"] = round4(servo_error_m_);
    row["servo_rad"] = round4(servo_error_rad_);
  }
  last_tick_s_ = now;
  std::string text = row.dump(-1, ' ', false, nlohmann::ordered_json::error_handler_t::replace);
  if (runs_) runs_->on_row(text);
  plots_.append("plot", std::move(text));
}

void ConsoleNode::cell_moved() {
  if (cell_timer_ != 0) return;
  cell_tick();  // at once: a pose after a quiet spell is not held back
  cell_timer_ = ctx_.loop.every(std::chrono::nanoseconds(static_cast<long>(1e9 / kCellRateHz)), [this] { cell_tick(); });
}

void ConsoleNode::cell_tick() {
  if (!cell_.dirty()) {
    // Nothing came since the last tick: the timer stops until something moves.
    ctx_.loop.cancel(cell_timer_);
    cell_timer_ = 0;
    return;
  }
  const auto change = cell_.take_changes(wall_now_s());
  if (!change) return;
  if (runs_) runs_->on_cell(*change);
  state_.update_cell(*change);
}

// --- the HTTP side's requests, run on the loop ---

ActionResult ConsoleNode::on_loop(std::function<void(std::shared_ptr<std::promise<ActionResult>>)> work) {
  auto promise = std::make_shared<std::promise<ActionResult>>();
  auto answer = promise->get_future();
  ctx_.loop.post([promise, work = std::move(work)] { work(promise); });
  if (answer.wait_for(query_timeout_ + std::chrono::seconds(2)) != std::future_status::ready)
    return {false, "the console's DDS loop did not answer in time", {}};
  return answer.get();
}

ActionResult ConsoleNode::publish_recipe(const std::string& task_id, const std::string& recipe_json,
                                         const std::string& submitter) {
  return on_loop([=](auto promise) {
    if (recipes_.matched_readers() == 0) {
      promise->set_value({false, "no task controller reads recipes on this domain; nothing was sent", {}});
      return;
    }
    const dds_return_t rc = write_recipe(recipes_, task_id, recipe_json, submitter);
    promise->set_value({rc == DDS_RETCODE_OK, rc == DDS_RETCODE_OK ? "" : std::string("publishing failed: ") + dds_strretcode(rc), {}});
  });
}

ActionResult ConsoleNode::rehearse(const std::string& task_id, const std::string& recipe_json,
                                   const std::string& submitter) {
  // The real cell's running revision, which the rehearsal cell is brought to first; unknown (nothing
  // applied) when no world model answers on the cell's domain.
  CellTarget cell;
  if (rehearsal_) {
    world_protocol::CellRequest show;
    show.op = world_protocol::CellOp::kShow;
    const ActionResult shown = cell_request(show);
    const json result = shown.ok ? shown.data.value("result", json::object()) : json::object();
    cell.revision = result.value("cell_revision", std::uint64_t{0});
    cell.sha256 = result.value("sha256", "");
    cell.cell_json = result.value("cell_json", "");
  }
  return on_loop([=](auto promise) {
    if (!rehearsal_) {
      promise->set_value({false, "no rehearsal domain is configured", {}});
      return;
    }
    // The models the document pins go with it: the rehearsal world model's folder may lack them.
    CellTarget target = cell;
    const JsonParseResult doc = parse_json_bounded(target.cell_json.empty() ? "{}" : target.cell_json,
                                                   {cell::kMaxCellFileBytes, cell::kMaxCellFileDepth});
    for (const json& e : doc.ok() ? doc.value.value("entities", json::array()) : json::array()) {
      const json model = e.is_object() ? e.value("model", json::object()) : json::object();
      const auto kept = model.is_object() && model.value("sha256", json()).is_string()
                            ? models_by_sha_.find(model["sha256"].get<std::string>())
                            : models_by_sha_.end();
      if (kept != models_by_sha_.end()) target.models.push_back(kept->second);
    }
    rehearsal_->publish(task_id, recipe_json, submitter, target, promise);
  });
}

ActionResult ConsoleNode::rehearsal_cell() {
  return on_loop([this](auto promise) {
    promise->set_value({rehearsal_ != nullptr, "", rehearsal_ ? rehearsal_->cell_status() : nlohmann::json()});
  });
}

ActionResult ConsoleNode::task_command(const std::string& task_id, const std::string& kind, const std::string& reason,
                                       const std::string& issuer) {
  return on_loop([=](auto promise) {
    if (task_commands_.matched_readers() == 0) {
      promise->set_value({false, "no task controller reads task commands on this domain; nothing was sent", {}});
      return;
    }
    rigger_task_TaskCommand c{};
    c.task_id = dds::wire_string(task_id);
    c.kind = kind == "pause" ? rigger_task_TASK_PAUSE : kind == "resume" ? rigger_task_TASK_RESUME : rigger_task_TASK_CANCEL;
    c.reason = dds::wire_string(reason);
    c.issuer = dds::wire_string(issuer);
    c.seq = command_seq_++;
    c.stamp = dds::wire_now();
    const dds_return_t rc = task_commands_.write(c);
    promise->set_value({rc == DDS_RETCODE_OK, rc == DDS_RETCODE_OK ? "" : std::string("sending failed: ") + dds_strretcode(rc), {}});
  });
}

ActionResult ConsoleNode::answer_prompt(const std::string& prompt_id, const std::string& answer,
                                        const std::string& operator_id, const std::string& comment) {
  return on_loop([=](auto promise) {
    const dds_return_t rc = operator_protocol::write_response(responses_, prompt_id, answer, operator_id, comment);
    promise->set_value({rc == DDS_RETCODE_OK, rc == DDS_RETCODE_OK ? "" : std::string("sending failed: ") + dds_strretcode(rc), {}});
  });
}

ActionResult ConsoleNode::journal(const std::string& task_id) {
  return on_loop([=](auto promise) {
    if (journal_queries_.matched_readers() == 0) {
      promise->set_value({false, "no task controller answers journal queries on this domain", {}});
      return;
    }
    const std::uint64_t id = next_request_++;
    rigger_task_JournalQuery q{};
    q.client_id = dds::wire_string(client_id_);
    q.request_id = id;
    q.task_id = dds::wire_string(task_id);
    q.max_entries = 100000;
    journal_queries_.write(q);
    const auto timer = ctx_.loop.after(query_timeout_, [this, id] {
      auto it = journal_pending_.find(id);
      if (it == journal_pending_.end()) return;
      it->second.promise->set_value({false, "the task controller did not answer the journal query in time", {}});
      journal_pending_.erase(it);
    });
    journal_pending_[id] = {promise, timer};
  });
}

void ConsoleNode::on_journal_replies() {
  journal_replies_.take([this](const rigger_task_JournalReply& rep, const dds_sample_info_t&) {
    if (dds::to_string(rep.client_id) != client_id_) return;
    auto it = journal_pending_.find(rep.request_id);
    if (it == journal_pending_.end()) return;
    json entries = json::array();
    for (const auto& e : dds::elements(rep.entries)) {
      entries.push_back({{"stamp", seconds(e.stamp)}, {"node_id", dds::to_string(e.node_id)},
                         {"kind", dds::to_string(e.kind)}, {"code", dds::to_string(e.code)},
                         {"message", dds::to_string(e.message)}});
    }
    ctx_.loop.cancel(it->second.timer);
    it->second.promise->set_value({rep.ok, dds::to_string(rep.message), std::move(entries)});
    journal_pending_.erase(it);
  });
}

ActionResult ConsoleNode::world_entity(const std::string& id) {
  return on_loop([=](auto promise) {
    world_->entity(id, query_timeout_, [promise](const world_client::Reply& r) {
      promise->set_value({r.ok, r.ok ? "" : r.code + ": " + r.message, r.result});
    });
  });
}

ActionResult ConsoleNode::world_list() {
  return on_loop([=](auto promise) {
    world_->list(query_timeout_, [promise](const world_client::Reply& r) {
      promise->set_value({r.ok, r.ok ? "" : r.code + ": " + r.message, r.result});
    });
  });
}

ActionResult ConsoleNode::cad(const std::string& kind, const std::string& model, const std::string& args_json) {
  static const std::map<std::string, rigger_cad_CadRequestKind> kinds = {{"features", rigger_cad_CAD_FEATURES},
                                                                         {"tessellation", rigger_cad_CAD_TESSELLATION},
                                                                         {"frame", rigger_cad_CAD_FRAME},
                                                                         {"derive", rigger_cad_CAD_DERIVE}};
  const auto k = kinds.find(kind);
  if (k == kinds.end()) return {false, "no CAD request kind " + kind, {}};
  return cad_request(k->second, model, args_json, {}, query_timeout_);
}

ActionResult ConsoleNode::cad_load(const std::string& name, std::string step, const std::string& args_json) {
  // Reading a large STEP file takes the CAD service seconds (a minute for the largest it accepts).
  return cad_request(rigger_cad_CAD_LOAD, name, args_json, std::move(step), std::max(query_timeout_, kCadLoadTimeout));
}

ActionResult ConsoleNode::cad_request(rigger_cad_CadRequestKind kind, const std::string& model, const std::string& args_json,
                                      std::string content, std::chrono::milliseconds timeout) {
  auto bytes = std::make_shared<std::vector<std::uint8_t>>(content.begin(), content.end());
  content.clear();
  return on_loop([=](auto promise) {
    if (cad_requests_.matched_readers() == 0) {
      promise->set_value({false, "no CAD service on this domain", {}});
      return;
    }
    const std::uint64_t id = next_request_++;
    rigger_cad_CadRequest q{};
    q.client_id = dds::wire_string(client_id_);
    q.request_id = id;
    q.kind = kind;
    q.model = dds::wire_string(model);
    q.args_json = dds::wire_string(args_json);
    dds::wire_sequence(q.content, *bytes);
    cad_requests_.write(q);
    const auto timer = ctx_.loop.after(timeout, [this, id] {
      auto it = cad_pending_.find(id);
      if (it == cad_pending_.end()) return;
      it->second.promise->set_value({false, "the CAD service did not answer in time", {}});
      cad_pending_.erase(it);
    });
    cad_pending_[id] = {promise, timer};
  });
}

void ConsoleNode::on_cad_replies() {
  cad_replies_.take([this](const rigger_cad_CadReply& rep, const dds_sample_info_t&) {
    if (dds::to_string(rep.client_id) != client_id_) return;
    auto it = cad_pending_.find(rep.request_id);
    if (it == cad_pending_.end()) return;
    ctx_.loop.cancel(it->second.timer);
    if (!rep.ok) {
      it->second.promise->set_value({false, dds::to_string(rep.code) + ": " + dds::to_string(rep.message), {}});
    } else {
      const auto bytes = dds::elements(rep.data);
      std::string data(reinterpret_cast<const char*>(bytes.data()), bytes.size());
      JsonParseResult parsed = parse_json_bounded(dds::to_string(rep.result_json), {16U * 1024U * 1024U, 64});
      json result = parsed.ok() ? std::move(parsed.value) : json::object();
      it->second.promise->set_value(
          {true, "", json{{"model_sha256", dds::to_string(rep.model_sha256)}, {"result", std::move(result)}, {"data", std::move(data)}}});
    }
    cad_pending_.erase(it);
  });
}

ActionResult ConsoleNode::cell_request(const world_protocol::CellRequest& request) {
  return on_loop([=](auto promise) {
    if (cell_requests_.matched_readers() == 0) {
      promise->set_value({false, "no world model answers cell requests on this domain", {}});
      return;
    }
    world_protocol::CellRequest q = request;
    q.client_id = client_id_;
    q.request_id = next_request_++;
    rigger_world_CellRequest wire{};
    std::vector<rigger_world_CellModel> models;
    world_protocol::to_wire(q, wire, models);
    if (const dds_return_t rc = cell_requests_.write(wire); rc != DDS_RETCODE_OK) {
      promise->set_value({false, std::string("the cell request was not sent: ") + dds_strretcode(rc), {}});
      return;
    }
    const auto timer = ctx_.loop.after(query_timeout_, [this, id = q.request_id] {
      auto it = cell_pending_.find(id);
      if (it == cell_pending_.end()) return;
      it->second.promise->set_value({false, "the world model did not answer the cell request in time", {}});
      cell_pending_.erase(it);
    });
    cell_pending_[q.request_id] = {promise, timer};
  });
}

ActionResult ConsoleNode::cell_models(const std::string& sha256) {
  return on_loop([this, sha256](auto promise) {
    if (sha256.empty()) {
      std::vector<const world_protocol::CellModel*> kept;
      for (const auto& [sha, m] : models_by_sha_) kept.push_back(&m);
      std::sort(kept.begin(), kept.end(), [](const auto* a, const auto* b) { return a->name < b->name; });
      nlohmann::json list = nlohmann::json::array();
      for (const auto* m : kept) list.push_back({{"name", m->name}, {"sha256", m->sha256}, {"bytes", m->step.size()}});
      promise->set_value({true, "", std::move(list)});
      return;
    }
    const auto it = models_by_sha_.find(sha256);
    if (it == models_by_sha_.end()) {
      promise->set_value({false, "the cell's running revision pins no model of sha256 " + sha256, {}});
      return;
    }
    const world_protocol::CellModel& m = it->second;
    promise->set_value({true, "", {{"name", m.name}, {"sha256", m.sha256}, {"step", m.step}}});
  });
}

void ConsoleNode::on_cell_models() {
  // The world model publishes only the running revision's pinned models and disposes the others.
  static constexpr std::size_t kMaxModels = 64;
  cell_models_.take(
      [this](const rigger_world_CellModel& w, const dds_sample_info_t&) {
        world_protocol::CellModel m = world_protocol::from_wire(w);
        if (models_by_sha_.size() >= kMaxModels && models_by_sha_.count(m.sha256) == 0) {
          ctx_.log->warn("cell model not kept for rehearsals: {} models kept already sha256={}", kMaxModels, m.sha256);
          return;
        }
        models_by_sha_[m.sha256] = std::move(m);
      },
      [this](const rigger_world_CellModel& key, const dds_sample_info_t&) {
        models_by_sha_.erase(dds::to_string(key.sha256));
      });
}

void ConsoleNode::on_cell_replies() {
  cell_replies_.take([this](const rigger_world_CellReply& w, const dds_sample_info_t&) {
    const world_protocol::CellReply rep = world_protocol::from_wire(w);
    if (rep.client_id != client_id_) return;
    auto it = cell_pending_.find(rep.request_id);
    if (it == cell_pending_.end()) return;
    ctx_.loop.cancel(it->second.timer);
    JsonParseResult parsed = parse_json_bounded(rep.result_json.empty() ? "{}" : rep.result_json, {16U * 1024U * 1024U, 64});
    it->second.promise->set_value(
        {rep.ok, rep.message,
         json{{"code", rep.code}, {"cell_revision", rep.cell_revision}, {"result", parsed.ok() ? std::move(parsed.value) : json::object()}}});
    cell_pending_.erase(it);
  });
}

void ConsoleNode::on_cell_revisions() {
  cell_revisions_.take([this](const rigger_world_CellRevision& w, const dds_sample_info_t&) {
    const world_protocol::CellRevision r = world_protocol::from_wire(w);
    JsonParseResult changes = parse_json_bounded(r.changes_json.empty() ? "{}" : r.changes_json, {4U * 1024U * 1024U, 16});
    state_.update_revision({{"cell_revision", r.cell_revision},
                            {"previous_revision", r.previous_revision},
                            {"sha256", r.sha256},
                            {"who", r.who},
                            {"comment", r.comment},
                            {"stamp", std::chrono::duration<double>(r.stamp.time_since_epoch()).count()},
                            {"changes", changes.ok() ? std::move(changes.value) : json::object()}});
  });
}

}  // namespace rigger::console
