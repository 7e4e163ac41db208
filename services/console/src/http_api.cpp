#include "http_api.hpp"

#include <ctime>
#include <fstream>

#include <httplib.h>

#include "http_replies.hpp"
#include "rigger/base/bounded_json.hpp"
#include "rigger/base/config.hpp"

namespace rigger::console {

using nlohmann::json;
using Clock = std::chrono::steady_clock;

namespace {

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

}  // namespace

HttpApi::HttpApi(HttpConfig config, Users users, ConsoleState& state, EventLog& events, EventLog& plots,
                 Backend& backend, SkillCatalog& skills, Logger log, std::optional<RehearsalFeed> rehearsal,
                 const RunArchive* runs)
    : config_(std::move(config)),
      streams_(config_.max_streams),
      users_(std::move(users)),
      state_(state),
      events_(events),
      plots_(plots),
      backend_(backend),
      skills_(skills),
      log_(std::move(log)),
      rehearsal_(std::move(rehearsal)),
      runs_(runs) {}

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
  const int threads = config_.max_streams + HttpConfig::kRequestThreads;
  server_->new_task_queue = [threads] { return new httplib::ThreadPool(static_cast<std::size_t>(threads)); };
  // A STEP file sent to the Planner's import may be larger than any other body: the pre-routing handler
  // (routes()) refuses the others above max_body_bytes before they are read.
  server_->set_payload_max_length(std::max(config_.max_body_bytes, config_.max_import_bytes));
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
  append_audit(json{{"time", utc_now()}, {"user", user.name}, {"role", role_name(user.role)}, {"action", action},
                    {"target", target}, {"result", result}});
}

void HttpApi::audit_system(const std::string& action, const std::string& target, const std::string& result,
                           const std::string& who) {
  log_->info("action user=console role=system action={} target={} result={} by={}", action, target, result, who);
  append_audit(json{{"time", utc_now()}, {"user", "console"}, {"role", "system"}, {"action", action},
                    {"target", target}, {"result", result}, {"by", who}});
}

void HttpApi::append_audit(const json& line) {
  if (config_.audit_log.empty()) return;
  std::lock_guard lock(audit_mutex_);
  std::ofstream out(config_.audit_log, std::ios::app);
  out << to_text(line) << "\n";
}

std::string HttpApi::new_confirmation(Pending p) {
  std::lock_guard lock(pending_mutex_);
  const auto now = Clock::now();
  for (auto it = pending_.begin(); it != pending_.end();) it = it->second.deadline < now ? pending_.erase(it) : std::next(it);
  const std::string id = random_hex(16);
  pending_[id] = std::move(p);
  return id;
}

std::optional<User> HttpApi::who(const httplib::Request& req, httplib::Response& res, Role needed, bool stream) {
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
}

std::optional<json> HttpApi::body(const httplib::Request& req, httplib::Response& res) {
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
}

void HttpApi::routes() {
  auto& s = *server_;
  s.set_error_handler([](const httplib::Request& req, httplib::Response& res) {
    if (!res.body.empty()) return;
    switch (res.status) {
      case 404: send_error(res, 404, "no such page or endpoint", req.path); break;
      case 413: send_error(res, 413, "the body is larger than the console accepts", req.path); break;
      case 400: send_error(res, 400, "malformed request", req.path); break;
      default: send_error(res, res.status, "request failed", req.path); break;
    }
  });
  s.set_pre_routing_handler([this](const httplib::Request& req, httplib::Response& res) {
    res.set_header("X-Content-Type-Options", "nosniff");
    if (req.path.rfind("/api/", 0) == 0) res.set_header("Cache-Control", "no-store");
    const std::size_t limit = req.path == kImportPath ? config_.max_import_bytes : config_.max_body_bytes;
    if (req.get_header_value<std::uint64_t>("Content-Length") > limit) {
      res.set_header("Connection", "close");
      send_error(res, 413,
                 "the body is larger than the console accepts here (" + std::to_string(limit) + " bytes)", req.path);
      return httplib::Server::HandlerResponse::Handled;
    }
    return httplib::Server::HandlerResponse::Unhandled;
  });

  // The first route whose method and path match a request answers it (cpp-httplib tries them in the
  // order registered); paths are regular expressions, the groups in req.matches.
  enum class Method { kGet, kPost };
  struct Route {
    Method method;
    const char* path;
    Handler handler;
  };
  static const Route kRoutes[] = {
      // reads (http_read_routes.cpp)
      {Method::kGet, "/api/me", &HttpApi::get_me},
      {Method::kGet, "/api/state", &HttpApi::get_state},
      {Method::kGet, "/api/events", &HttpApi::get_events},
      {Method::kGet, "/api/plots/stream", &HttpApi::get_plots_stream},
      {Method::kGet, "/api/plots", &HttpApi::get_plots},
      {Method::kGet, "/api/journal", &HttpApi::get_journal},
      {Method::kGet, "/api/runs", &HttpApi::get_runs},
      {Method::kGet, R"(/api/runs/([^/]+)/plots)", &HttpApi::get_run_plots},
      {Method::kGet, R"(/api/runs/([^/]+)/cell)", &HttpApi::get_run_cell},
      {Method::kGet, "/api/world/entities", &HttpApi::get_world_entities},
      {Method::kGet, R"(/api/world/entity/([A-Za-z0-9_.:-]+))", &HttpApi::get_world_entity},
      {Method::kGet, "/api/cad/model.glb", &HttpApi::get_cad_model},
      {Method::kGet, "/api/cad/features", &HttpApi::get_cad_features},
      {Method::kGet, "/api/cad/parts", &HttpApi::get_cad_parts},
      {Method::kGet, "/api/skills", &HttpApi::get_skills},
      // cell revisions (http_cell_routes.cpp)
      {Method::kGet, "/api/cell", &HttpApi::get_cell},
      {Method::kGet, "/api/cell/history", &HttpApi::get_cell_history},
      {Method::kPost, "/api/cell/revisions", &HttpApi::post_cell_revision},
      // the planner and the rehearsal cell (http_planner_routes.cpp)
      {Method::kPost, "/api/planner/validate", &HttpApi::post_planner_validate},
      {Method::kPost, "/api/planner/screws", &HttpApi::post_planner_screws},
      {Method::kPost, "/api/planner/frame", &HttpApi::post_planner_frame},
      {Method::kPost, "/api/planner/place", &HttpApi::post_planner_place},
      {Method::kPost, kImportPath, &HttpApi::post_planner_import},
      {Method::kPost, "/api/planner/import/node", &HttpApi::post_planner_import_node},
      {Method::kGet, "/api/planner/cell_models", &HttpApi::get_planner_cell_models},
      {Method::kPost, "/api/planner/declare", &HttpApi::post_planner_declare},
      {Method::kPost, "/api/planner/add", &HttpApi::post_planner_add},
      {Method::kPost, "/api/planner/replace", &HttpApi::post_planner_replace},
      {Method::kGet, "/api/rehearsal/state", &HttpApi::get_rehearsal_state},
      {Method::kGet, "/api/rehearsal/events", &HttpApi::get_rehearsal_events},
      {Method::kPost, "/api/planner/rehearse", &HttpApi::post_planner_rehearse},
      {Method::kGet, "/api/rehearsal/cell", &HttpApi::get_rehearsal_cell},
      // commands (http_command_routes.cpp)
      {Method::kPost, "/api/recipes", &HttpApi::post_recipe},
      {Method::kPost, R"(/api/tasks/([^/]+)/resume)", &HttpApi::post_task_resume},
      {Method::kPost, "/api/confirm", &HttpApi::post_confirm},
      {Method::kPost, R"(/api/tasks/([^/]+)/cancel)", &HttpApi::post_task_cancel},
      {Method::kPost, R"(/api/tasks/([^/]+)/pause)", &HttpApi::post_task_pause},
      {Method::kPost, R"(/api/tasks/([^/]+)/stop)", &HttpApi::post_task_stop},
      {Method::kPost, R"(/api/prompts/([^/]+)/answer)", &HttpApi::post_prompt_answer},
  };
  for (const Route& route : kRoutes) {
    auto handler = [this, member = route.handler](const httplib::Request& req, httplib::Response& res) {
      (this->*member)(req, res);
    };
    if (route.method == Method::kGet)
      s.Get(route.path, handler);
    else
      s.Post(route.path, handler);
  }
}

}  // namespace rigger::console
