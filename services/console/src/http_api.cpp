#include "http_api.hpp"

#include <algorithm>
#include <ctime>
#include <fstream>

#include <httplib.h>

#include "rigger/base/config.hpp"
#include "rigger/base/bounded_json.hpp"

namespace rigger::console {

using nlohmann::json;
using Clock = std::chrono::steady_clock;

namespace {

constexpr std::size_t kMaxEventsPerWrite = 512;
constexpr std::chrono::milliseconds kKeepAlive{15000};

// Content types chosen so that cpp-httplib does not compress: 0.11 compresses with brotli at quality 11
// whenever the browser accepts br (every browser does) and the type is in its exact list (text/*,
// application/json, application/javascript): that cost 1.8 s of CPU per page load for three.js and
// 0.5 s per validation of a 1,000-node tree (bench_planner_tree); gzip would be 36 ms, but the library
// prefers br and gives no way to choose. The console serves a LAN, where the bytes cost less than that:
// JSON and JavaScript go uncompressed (three.js, 1.3 MB, in 2 ms on loopback). See docs/console.md.
constexpr const char* kJson = "application/json; charset=utf-8";
constexpr const char* kJavaScript = "application/javascript; charset=utf-8";

// Strings from DDS or from requests are not checked for UTF-8: replace what is not, never throw.
std::string to_text(const json& j) { return j.dump(-1, ' ', false, json::error_handler_t::replace); }

void send_error(httplib::Response& res, int status, const std::string& error, const std::string& where) {
  res.status = status;
  res.set_content(to_text(json{{"error", error}, {"where", where}}), kJson);
}

/// `body[key]` when it is a string, else "".
std::string text_field(const json& body, const char* key) {
  const auto it = body.find(key);
  return it != body.end() && it->is_string() ? it->get<std::string>() : "";
}

/// The CAD service did not answer a planner request: a refusal of the picks (a CAD_ code: stale, not a
/// hole, not perpendicular, off the face) is the request's fault (400, at `picks` in the body); no
/// answer is the cell's (503).
void send_cad_refusal(httplib::Response& res, const httplib::Request& req, const std::string& message,
                      const std::string& picks) {
  const bool refused = message.rfind("CAD_", 0) == 0;
  send_error(res, refused ? 400 : 503, "the CAD service: " + message, req.path + (refused ? picks : ""));
}

void send_json(httplib::Response& res, const json& body, int status = 200) {
  res.status = status;
  res.set_content(to_text(body), kJson);
}

std::string bearer(const httplib::Request& req) {
  const std::string h = req.get_header_value("Authorization");
  const std::string prefix = "Bearer ";
  return h.compare(0, prefix.size(), prefix) == 0 ? h.substr(prefix.size()) : "";
}

std::string cookie_token(const httplib::Request& req) {
  const std::string c = req.get_header_value("Cookie");
  const std::string key = "rigger_token=";
  for (std::size_t pos = 0; pos < c.size();) {
    while (pos < c.size() && (c[pos] == ' ' || c[pos] == ';')) ++pos;
    const std::size_t end = c.find(';', pos);
    const std::string item = c.substr(pos, end == std::string::npos ? std::string::npos : end - pos);
    if (item.compare(0, key.size(), key) == 0) return item.substr(key.size());
    if (end == std::string::npos) break;
    pos = end + 1;
  }
  return "";
}

std::string utc_now() {
  const auto now = std::chrono::system_clock::now();
  const std::time_t t = std::chrono::system_clock::to_time_t(now);
  const auto ms = std::chrono::duration_cast<std::chrono::milliseconds>(now.time_since_epoch()).count() % 1000;
  std::tm tm{};
  gmtime_r(&t, &tm);
  char buf[80];
  std::snprintf(buf, sizeof buf, "%04d-%02d-%02dT%02d:%02d:%02d.%03dZ", tm.tm_year + 1900, tm.tm_mon + 1, tm.tm_mday,
                tm.tm_hour, tm.tm_min, tm.tm_sec, static_cast<int>(ms));
  return buf;
}

// The SSE frames of a batch: "id", "event" and "data" lines; a reset tells the client to reload the state.
std::string sse_frames(const EventLog& log, const EventBatch& batch) {
  std::string out;
  if (batch.reset) out += "id: " + log.id_of(batch.last_seq) + "\nevent: reset\ndata: {}\n\n";
  for (const auto& e : batch.events) out += "id: " + log.id_of(e.seq) + "\nevent: " + e.type + "\ndata: " + e.data + "\n\n";
  return out;
}

}  // namespace

HttpApi::HttpApi(HttpConfig config, Users users, ConsoleState& state, EventLog& events, EventLog& plots,
                 Backend& backend, SkillCatalog& skills, Logger log, std::optional<RehearsalFeed> rehearsal)
    : config_(std::move(config)),
      users_(std::move(users)),
      state_(state),
      events_(events),
      plots_(plots),
      backend_(backend),
      skills_(skills),
      log_(std::move(log)),
      rehearsal_(std::move(rehearsal)) {}

HttpApi::~HttpApi() { stop(); }

void HttpApi::start() {
  if (tls()) {
    auto ssl = std::make_unique<httplib::SSLServer>(config_.tls_cert.c_str(), config_.tls_key.c_str());
    if (!ssl->is_valid())
      throw ConfigError(config_.config_file, "/tls_cert", "cannot use the TLS certificate " + config_.tls_cert + " with key " + config_.tls_key);
    server_ = std::move(ssl);
  } else {
    server_ = std::make_unique<httplib::Server>();
  }
  const int threads = config_.threads;
  server_->new_task_queue = [threads] { return new httplib::ThreadPool(static_cast<std::size_t>(threads)); };
  server_->set_payload_max_length(config_.max_body_bytes);
  // A worker holds an idle keep-alive connection, or a connection the browser opened ahead and has sent
  // nothing on, until these run out, and stop() waits for every worker: with 30 s (and the library's
  // 5 s read timeout) the console took 7-10 s to stop. Reconnecting on a LAN costs far less.
  server_->set_keep_alive_timeout(2);
  server_->set_read_timeout(2, 0);
  // A response's headers and body are two writes: without TCP_NODELAY the body waits for the client's
  // delayed ACK of the headers (40 ms on Linux), on every small answer.
  server_->set_tcp_nodelay(true);
  server_->set_file_extension_and_mimetype_mapping("mjs", kJavaScript);
  server_->set_file_extension_and_mimetype_mapping("js", kJavaScript);
  server_->set_file_extension_and_mimetype_mapping("glb", "model/gltf-binary");
  routes();
  if (!server_->set_mount_point("/", config_.web_dir))
    throw ConfigError(config_.config_file, "/web_dir", "no folder " + config_.web_dir + " to serve the pages from");
  if (config_.port == 0) {
    port_ = server_->bind_to_any_port(config_.address);
  } else {
    port_ = server_->bind_to_port(config_.address, config_.port) ? config_.port : -1;
  }
  if (port_ <= 0)
    throw ConfigError(config_.config_file, "/port",
                      "cannot listen on " + config_.address + ":" + std::to_string(config_.port) + " (in use, or not an address of this host)");
  thread_ = std::thread([this] { server_->listen_after_bind(); });
  log_->info("listening address={} port={} tls={} web={}", config_.address, port_, tls(), config_.web_dir);
}

void HttpApi::stop() {
  events_.close();
  plots_.close();
  if (rehearsal_) rehearsal_->events.close();
  if (server_) server_->stop();
  if (thread_.joinable()) thread_.join();
}

void HttpApi::audit(const User& user, const std::string& action, const std::string& target, const std::string& result) {
  log_->info("action user={} role={} action={} target={} result={}", user.name, role_name(user.role), action, target,
             result);
  if (config_.audit_log.empty()) return;
  std::lock_guard lock(audit_mutex_);
  std::ofstream out(config_.audit_log, std::ios::app);
  out << to_text(json{{"time", utc_now()}, {"user", user.name}, {"role", role_name(user.role)}, {"action", action},
                      {"target", target}, {"result", result}})
      << "\n";
}

std::string HttpApi::new_confirmation(Pending p) {
  std::lock_guard lock(pending_mutex_);
  const auto now = Clock::now();
  for (auto it = pending_.begin(); it != pending_.end();) it = it->second.deadline < now ? pending_.erase(it) : std::next(it);
  const std::string id = random_hex(16);
  pending_[id] = std::move(p);
  return id;
}

void HttpApi::routes() {
  auto& s = *server_;

  // Who is asking, and may they? Sends 401/403 and returns nullopt when not. Only the event streams
  // take the token from the query (?token=) or the rigger_token cookie: EventSource cannot set headers.
  const auto who = [this](const httplib::Request& req, httplib::Response& res, Role needed,
                          bool stream = false) -> std::optional<User> {
    std::string token = bearer(req);
    if (token.empty() && stream) token = req.has_param("token") ? req.get_param_value("token") : cookie_token(req);
    if (token.empty()) {
      send_error(res, 401, "no bearer token (log in with the link the console's setup printed)", req.path);
      return std::nullopt;
    }
    auto user = users_.authenticate(token);
    if (!user) {
      send_error(res, 401, "unknown token", req.path);
      return std::nullopt;
    }
    if (static_cast<int>(user->role) < static_cast<int>(needed)) {
      send_error(res, 403,
                 std::string("user ") + user->name + " is a " + role_name(user->role) + "; this needs a " +
                     role_name(needed),
                 req.path);
      return std::nullopt;
    }
    return user;
  };
  // The request body as a JSON object, parsed within bounds; sends 400 and returns nullopt otherwise.
  const auto body = [this](const httplib::Request& req, httplib::Response& res) -> std::optional<json> {
    if (req.body.empty()) return json::object();
    rigger::JsonLimits limits;
    limits.max_bytes = config_.max_body_bytes;
    limits.max_depth = 64;
    auto parsed = rigger::parse_json_bounded(req.body, limits);
    if (!parsed.ok()) {
      send_error(res, 400, "the body is not acceptable JSON: " + parsed.error->to_string(), req.path);
      return std::nullopt;
    }
    if (!parsed.value.is_object()) {
      send_error(res, 400, "the body must be a JSON object", req.path);
      return std::nullopt;
    }
    return std::move(parsed.value);
  };
  // Streams `log` as Server-Sent Events from the client's Last-Event-ID (header, or last_event_id in
  // the query), or from `start` when it has none.
  const auto stream = [](EventLog& log, const httplib::Request& req, httplib::Response& res, std::uint64_t start) {
    std::string last = req.get_header_value("Last-Event-ID");
    if (last.empty() && req.has_param("last_event_id")) last = req.get_param_value("last_event_id");
    auto from = std::make_shared<std::uint64_t>(start);
    auto reset = std::make_shared<bool>(false);
    if (!last.empty()) {
      if (const auto seq = log.parse_id(last)) *from = *seq;
      else *reset = true;  // an id of an earlier run of the console: the client reloads the state
    }
    res.set_header("Cache-Control", "no-store");
    res.set_header("X-Accel-Buffering", "no");
    res.set_chunked_content_provider("text/event-stream", [&log, from, reset](std::size_t, httplib::DataSink& sink) {
      if (log.closed()) return false;
      std::string out;
      if (*reset) {
        *reset = false;
        *from = log.last_seq();
        out = "retry: 1000\nid: " + log.id_of(*from) + "\nevent: reset\ndata: {}\n\n";
      } else {
        const EventBatch batch = log.wait_after(*from, kMaxEventsPerWrite, kKeepAlive);
        if (log.closed()) return false;
        *from = batch.last_seq;
        out = batch.events.empty() && !batch.reset ? std::string(": keep-alive\n\n") : sse_frames(log, batch);
      }
      return sink.is_writable() && sink.write(out.data(), out.size());
    });
  };

  s.set_error_handler([](const httplib::Request& req, httplib::Response& res) {
    if (!res.body.empty()) return;
    switch (res.status) {
      case 404: send_error(res, 404, "no such page or endpoint", req.path); break;
      case 413: send_error(res, 413, "the body is larger than the console accepts", req.path); break;
      case 400: send_error(res, 400, "malformed request", req.path); break;
      default: send_error(res, res.status, "request failed", req.path); break;
    }
  });
  s.set_pre_routing_handler([](const httplib::Request& req, httplib::Response& res) {
    res.set_header("X-Content-Type-Options", "nosniff");
    if (req.path.rfind("/api/", 0) == 0) res.set_header("Cache-Control", "no-store");
    return httplib::Server::HandlerResponse::Unhandled;
  });

  // --- reads ---
  s.Get("/api/me", [=](const httplib::Request& req, httplib::Response& res) {
    if (auto u = who(req, res, Role::kViewer)) send_json(res, {{"user", u->name}, {"role", role_name(u->role)}});
  });
  s.Get("/api/state", [=](const httplib::Request& req, httplib::Response& res) {
    if (who(req, res, Role::kViewer)) send_json(res, state_.snapshot(req.has_param("task") ? req.get_param_value("task") : ""));
  });
  s.Get("/api/events", [=](const httplib::Request& req, httplib::Response& res) {
    if (who(req, res, Role::kViewer, true)) stream(events_, req, res, events_.last_seq());
  });
  s.Get("/api/plots/stream", [=](const httplib::Request& req, httplib::Response& res) {
    if (who(req, res, Role::kViewer, true)) stream(plots_, req, res, plots_.last_seq());
  });
  s.Get("/api/plots", [=](const httplib::Request& req, httplib::Response& res) {
    if (!who(req, res, Role::kViewer)) return;
    double from = 0, to = 1e300;
    try {
      if (req.has_param("from")) from = std::stod(req.get_param_value("from"));
      if (req.has_param("to")) to = std::stod(req.get_param_value("to"));
    } catch (const std::exception&) {
      return send_error(res, 400, "from and to are times in seconds since the epoch", req.path);
    }
    std::string out = "[";
    bool first = true;
    for (const auto& e : plots_.retained()) {
      // Rows start with {"t":<seconds>, ...}: read t without parsing the whole row.
      const double t = std::strtod(e.data.c_str() + 5, nullptr);
      if (t < from || t > to) continue;
      if (!first) out += ",";
      out += e.data;
      first = false;
    }
    out += "]";
    res.set_content(out, kJson);
  });
  s.Get("/api/journal", [=](const httplib::Request& req, httplib::Response& res) {
    if (!who(req, res, Role::kViewer)) return;
    const std::string task = req.has_param("task") ? req.get_param_value("task") : "";
    const auto r = backend_.journal(task);
    if (!r.ok) return send_error(res, 503, r.message, req.path);
    send_json(res, {{"task_id", task}, {"entries", r.data}});
  });
  s.Get(R"(/api/world/entity/([A-Za-z0-9_.:-]+))", [=](const httplib::Request& req, httplib::Response& res) {
    if (!who(req, res, Role::kViewer)) return;
    const auto r = backend_.world_entity(req.matches[1]);
    if (!r.ok) return send_error(res, 503, r.message, req.path);
    send_json(res, r.data);
  });
  s.Get("/api/cad/model.glb", [=](const httplib::Request& req, httplib::Response& res) {
    if (!who(req, res, Role::kViewer)) return;
    const std::string model = req.has_param("model") ? req.get_param_value("model") : "object:target";
    const auto r = backend_.cad("tessellation", model, "{}");
    if (!r.ok) return send_error(res, 503, r.message, req.path);
    res.set_content(r.data.at("data").get_ref<const std::string&>(), "model/gltf-binary");
  });
  // The planner's reads: the model's features (holes, faces with signatures) and which GLB primitive is
  // which face (the tessellation's "parts").
  const auto cad_read = [=](const char* kind, const char* what) {
    return [=](const httplib::Request& req, httplib::Response& res) {
      if (!who(req, res, Role::kViewer)) return;
      const std::string model = req.has_param("model") ? req.get_param_value("model") : "object:target";
      const auto r = backend_.cad(kind, model, "{}");
      if (!r.ok) return send_error(res, 503, std::string("the ") + what + " of " + model + ": " + r.message, req.path);
      json out = r.data.value("result", json::object());
      out["model"] = model;
      send_json(res, out);
    };
  };
  s.Get("/api/cad/features", cad_read("features", "features"));
  s.Get("/api/cad/parts", cad_read("tessellation", "tessellation parts"));
  s.Get("/api/skills", [=](const httplib::Request& req, httplib::Response& res) {
    if (who(req, res, Role::kViewer)) send_json(res, skills_.to_json());
  });

  // --- the planner ---
  // Validation by the controller's own validator against the live library; the answer is 200 either way
  // (ok and errors by JSON pointer), 400 only for a body that is not a recipe at all.
  s.Post("/api/planner/validate", [=](const httplib::Request& req, httplib::Response& res) {
    if (!who(req, res, Role::kProgrammer)) return;
    send_json(res, validate_recipe(skills_.library(), req.body));
  });
  // The screw list of picked holes: derived by the CAD service, matched to the world model's screw holes.
  s.Post("/api/planner/screws", [=](const httplib::Request& req, httplib::Response& res) {
    if (!who(req, res, Role::kProgrammer)) return;
    auto b = body(req, res);
    if (!b) return;
    try {
      const ScrewRequest request = parse_screw_request(*b);
      const auto derived =
          backend_.cad("derive", request.model, json{{"parameter", "screw_list"}, {"holes", request.holes}}.dump());
      if (!derived.ok) return send_cad_refusal(res, req, derived.message, "#/holes");
      const auto entity = backend_.world_entity(request.entity);
      if (!entity.ok) return send_error(res, 503, "the world model: " + entity.message, req.path);
      send_json(res, screws_with_features(request, derived.data.value("model_sha256", ""),
                                          derived.data.value("result", json::object()), entity.data));
    } catch (const PlannerError& e) {
      send_error(res, 400, e.message, req.path + (e.pointer.empty() ? "" : "#" + e.pointer));
    }
  });

  // A pose parameter from picks: the CAD service's frame rule, as a pose in the part's frame.
  s.Post("/api/planner/frame", [=](const httplib::Request& req, httplib::Response& res) {
    if (!who(req, res, Role::kProgrammer)) return;
    auto b = body(req, res);
    if (!b) return;
    try {
      const FrameRequest request = parse_frame_request(*b);
      const auto framed = backend_.cad("frame", request.model, request.args.dump());
      if (!framed.ok) return send_cad_refusal(res, req, framed.message, "");
      const json result = framed.data.value("result", json::object());
      send_json(res, {{"model", request.model}, {"model_sha256", framed.data.value("model_sha256", "")},
                      {"args", request.args}, {"frame", result.value("frame", json())},
                      {"pose", pose_from_cad_frame(result, request.entity)}});
    } catch (const PlannerError& e) {
      send_error(res, 400, e.message, req.path + (e.pointer.empty() ? "" : "#" + e.pointer));
    }
  });

  // --- the rehearsal cell: the simulated cell on a domain of its own, where a recipe runs first ---
  // Its state and stream are /api/state's and /api/events' of that domain, kept apart from the cell's.
  const auto no_rehearsal = [](const httplib::Request& req, httplib::Response& res) {
    send_error(res, 409,
               "no rehearsal domain is configured: set rehearsal_domain in the console's configuration and run the "
               "simulated cell on that domain (docs/console.md, \"Rehearsal\")",
               req.path);
  };
  s.Get("/api/rehearsal/state", [=](const httplib::Request& req, httplib::Response& res) {
    if (!who(req, res, Role::kViewer)) return;
    if (!rehearsal_) return no_rehearsal(req, res);
    json snapshot = rehearsal_->state.snapshot(req.has_param("task") ? req.get_param_value("task") : "");
    snapshot["domain"] = rehearsal_->domain_id;
    send_json(res, snapshot);
  });
  s.Get("/api/rehearsal/events", [=](const httplib::Request& req, httplib::Response& res) {
    if (!who(req, res, Role::kViewer, true)) return;
    if (!rehearsal_) return no_rehearsal(req, res);
    stream(rehearsal_->events, req, res, rehearsal_->events.last_seq());
  });
  // Nothing real moves in a rehearsal, so it is one step (no confirmation), but journaled like a publish.
  s.Post("/api/planner/rehearse", [=](const httplib::Request& req, httplib::Response& res) {
    auto user = who(req, res, Role::kProgrammer);
    if (!user) return;
    if (!rehearsal_) {
      audit(*user, "rehearse", "", "refused: no rehearsal domain configured");
      return no_rehearsal(req, res);
    }
    auto recipe = body(req, res);
    if (!recipe) return;
    const std::string task_id = text_field(*recipe, "task_id");
    if (task_id.empty())
      return send_error(res, 400, "the recipe needs a non-empty string task_id", req.path + "#/task_id");
    const std::string domain = std::to_string(rehearsal_->domain_id);
    const auto refuse = [&](int status, const std::string& why, json errors = json::array()) {
      audit(*user, "rehearse", task_id, "refused: " + why);
      json answer = {{"error", why}, {"where", req.path}, {"domain", rehearsal_->domain_id}};
      if (!errors.empty()) answer["errors"] = std::move(errors);
      send_json(res, answer, status);
    };
    if (!rehearsal_->state.task(task_id).is_null())
      return refuse(409, "task " + task_id + " already ran on the rehearsal domain " + domain +
                             " and a controller takes a task id once: rehearse under a new task id");
    // The rehearsal controller's own verdict (its validator, against the library its executors announce).
    const auto r = backend_.rehearse(task_id, req.body, "console:" + user->name);
    const bool rejected = r.data.is_object() && r.data.value("state", "") == "REJECTED";
    if (rejected) return refuse(409, r.message, r.data.value("errors", json::array()));
    if (!r.ok) return refuse(503, r.message);
    audit(*user, "rehearse", task_id, "sent to rehearsal domain " + domain);
    send_json(res, {{"done", "rehearse"}, {"task_id", task_id}, {"domain", rehearsal_->domain_id},
                    {"state", r.data.value("state", "")}});
  });

  // --- commands ---
  s.Post("/api/recipes", [=](const httplib::Request& req, httplib::Response& res) {
    auto user = who(req, res, Role::kProgrammer);
    if (!user) return;
    auto recipe = body(req, res);
    if (!recipe) return;
    if (!recipe->contains("task_id") || !(*recipe)["task_id"].is_string() || (*recipe)["task_id"].get<std::string>().empty())
      return send_error(res, 400, "the recipe needs a non-empty string task_id", req.path + "#/task_id");
    const std::string task_id = (*recipe)["task_id"];
    const std::string id = new_confirmation({user->name, "publish", task_id, req.body, Clock::now() + config_.confirm_timeout});
    audit(*user, "select publish", task_id, "awaiting confirmation " + id);
    send_json(res, {{"confirmation_id", id}, {"action", "publish " + task_id},
                    {"expires_in_s", std::chrono::duration<double>(config_.confirm_timeout).count()}}, 202);
  });
  s.Post(R"(/api/tasks/([^/]+)/resume)", [=](const httplib::Request& req, httplib::Response& res) {
    auto user = who(req, res, Role::kProgrammer);
    if (!user) return;
    const std::string task_id = req.matches[1];
    const std::string id = new_confirmation({user->name, "resume", task_id, "", Clock::now() + config_.confirm_timeout});
    audit(*user, "select resume", task_id, "awaiting confirmation " + id);
    send_json(res, {{"confirmation_id", id}, {"action", "resume " + task_id},
                    {"expires_in_s", std::chrono::duration<double>(config_.confirm_timeout).count()}}, 202);
  });
  s.Post("/api/confirm", [=](const httplib::Request& req, httplib::Response& res) {
    auto user = who(req, res, Role::kViewer);
    if (!user) return;
    auto b = body(req, res);
    if (!b) return;
    const std::string id = text_field(*b, "confirmation_id");
    Pending p;
    {
      std::lock_guard lock(pending_mutex_);
      auto it = pending_.find(id);
      if (it == pending_.end() || it->second.user != user->name) {
        audit(*user, "confirm", id, "refused: unknown");
        return send_error(res, 409, "no pending action " + id + " of user " + user->name + " (already confirmed, or never selected)", req.path);
      }
      p = it->second;
      pending_.erase(it);
    }
    if (Clock::now() > p.deadline) {
      audit(*user, "confirm " + p.kind, p.task_id, "refused: expired");
      return send_error(res, 409,
                        "the confirmation of " + p.kind + " " + p.task_id + " expired (confirm within " +
                            std::to_string(config_.confirm_timeout.count() / 1000.0).substr(0, 4) + " s); select again",
                        req.path);
    }
    // Only programmers can have selected these; check again in case of a changed users file.
    if (static_cast<int>(user->role) < static_cast<int>(Role::kProgrammer))
      return send_error(res, 403, "only a programmer may " + p.kind, req.path);
    const auto r = p.kind == "publish"
                       ? backend_.publish_recipe(p.task_id, p.payload, "console:" + user->name)
                       : backend_.task_command(p.task_id, "resume", "resumed by " + user->name + " at the console",
                                               "console:" + user->name);
    audit(*user, p.kind, p.task_id, r.ok ? "sent" : "failed: " + r.message);
    if (!r.ok) return send_error(res, 503, r.message, req.path);
    send_json(res, {{"done", p.kind}, {"task_id", p.task_id}});
  });
  const auto command = [=](const std::string& kind, Role needed) {
    return [=](const httplib::Request& req, httplib::Response& res) {
      auto user = who(req, res, needed);
      if (!user) return;
      auto b = body(req, res);
      if (!b) return;
      const std::string task_id = req.matches[1];
      if (state_.task(task_id).is_null()) return send_error(res, 404, "no task " + task_id + " known", req.path);
      std::string reason = text_field(*b, "reason");
      const std::string wire_kind = kind == "stop" ? "cancel" : kind;
      reason = (kind == "stop" ? "STOP" : kind) + std::string(" by ") + user->name + " at the console" +
               (reason.empty() ? "" : ": " + reason);
      const auto r = backend_.task_command(task_id, wire_kind, reason, "console:" + user->name);
      audit(*user, kind, task_id, r.ok ? "sent" : "failed: " + r.message);
      if (!r.ok) return send_error(res, 503, r.message, req.path);
      send_json(res, {{"done", kind}, {"task_id", task_id}});
    };
  };
  s.Post(R"(/api/tasks/([^/]+)/cancel)", command("cancel", Role::kProgrammer));
  s.Post(R"(/api/tasks/([^/]+)/pause)", command("pause", Role::kOperator));
  s.Post(R"(/api/tasks/([^/]+)/stop)", command("stop", Role::kOperator));
  s.Post(R"(/api/prompts/([^/]+)/answer)", [=](const httplib::Request& req, httplib::Response& res) {
    auto user = who(req, res, Role::kOperator);
    if (!user) return;
    auto b = body(req, res);
    if (!b) return;
    const std::string prompt_id = req.matches[1];
    if (!b->contains("answer") || !(*b)["answer"].is_string())
      return send_error(res, 400, "expected {\"answer\": \"<one of the prompt's options>\"}", req.path + "#/answer");
    const std::string answer = (*b)["answer"];
    const json prompt = state_.prompt(prompt_id);
    if (prompt.is_null()) {
      audit(*user, "answer", prompt_id, "refused: not open");
      return send_error(res, 409, "prompt " + prompt_id + " is not open (answered, withdrawn or unknown)", req.path);
    }
    const auto& options = prompt["options"];
    if (std::find(options.begin(), options.end(), answer) == options.end())
      return send_error(res, 400, "\"" + answer + "\" is not one of the options " + to_text(options), req.path + "#/answer");
    const auto r = backend_.answer_prompt(prompt_id, answer, user->name, text_field(*b, "comment"));
    audit(*user, "answer " + answer, prompt_id, r.ok ? "sent" : "failed: " + r.message);
    if (!r.ok) return send_error(res, 503, r.message, req.path);
    send_json(res, {{"done", "answer"}, {"prompt_id", prompt_id}, {"answer", answer}});
  });
}

}  // namespace rigger::console
