#pragma once
/// @file
/// The console's HTTP side (cpp-httplib): authentication, roles, two-step confirmation, bounded
/// request bodies, the REST routes, the Server-Sent Event streams and the static pages. It never
/// touches a DDS object: reads come from ConsoleState and the plot EventLog, and everything that needs
/// DDS goes through a Backend, which the node implements by posting work to its event loop and waiting
/// for the answer.
#include <atomic>
#include <chrono>
#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include <nlohmann/json.hpp>

#include "auth.hpp"
#include "console_state.hpp"
#include "event_log.hpp"
#include "http_replies.hpp"
#include "imported_models.hpp"
#include "planner.hpp"
#include "run_archive.hpp"
#include "rigger/base/logging.hpp"
#include "rigger/world_protocol/cell_protocol.hpp"

namespace httplib {
class Server;
struct Request;
struct Response;
}

namespace rigger::console {

/// The outcome of a DDS action.
struct ActionResult {
  bool ok = false;
  std::string message;  ///< why not, when !ok
  nlohmann::json data;  ///< a query's answer
};

/// What the HTTP side asks of the DDS side. Every call blocks the calling HTTP thread (never the loop)
/// until the loop answered or a timeout passed. Thread-safe.
class Backend {
 public:
  virtual ~Backend() = default;
  /// Publishes a recipe on rigger/task/recipe with `submitter` as its submitter.
  virtual ActionResult publish_recipe(const std::string& task_id, const std::string& recipe_json,
                                      const std::string& submitter) = 0;
  /// Writes a task command; `kind` is "cancel", "pause" or "resume".
  virtual ActionResult task_command(const std::string& task_id, const std::string& kind, const std::string& reason,
                                    const std::string& issuer) = 0;
  /// Writes an operator response.
  virtual ActionResult answer_prompt(const std::string& prompt_id, const std::string& answer,
                                     const std::string& operator_id, const std::string& comment) = 0;
  /// The journal of `task_id` ("" : the task list) through the controller's query topics:
  /// data = [{"stamp", "node_id", "kind", "code", "message"}, ...].
  virtual ActionResult journal(const std::string& task_id) = 0;
  /// The world model's description of entity `id` (data = the entity JSON).
  virtual ActionResult world_entity(const std::string& id) = 0;
  /// The ids of every entity of the world model (data = a JSON array of strings).
  virtual ActionResult world_list() = 0;
  /// Asks the CAD service (docs/cad.md): `kind` is "features", "tessellation", "frame" or "derive";
  /// data = {"model_sha256", "result": <result_json parsed>, "data": <binary string, the GLB>}; a refusal
  /// is !ok with message "CODE: why".
  virtual ActionResult cad(const std::string& kind, const std::string& model, const std::string& args_json) = 0;
  /// Has the CAD service read a STEP file sent as bytes (CAD_LOAD with content; `name` is what it is
  /// called in messages; `args_json` "{}", or {"node": [...]} for one node of its product tree): data as
  /// cad()'s, the result being CAD_LOAD's (product tree, counts, holes; the node and its STEP bytes).
  virtual ActionResult cad_load(const std::string& name, std::string step, const std::string& args_json) = 0;
  /// Publishes a recipe on the rehearsal domain (the simulated cell where a recipe runs first) and waits
  /// for the rehearsal controller's verdict: data = its first status of the task ({"state": "ACCEPTED"
  /// or "RUNNING" ...}, ok; {"state": "REJECTED", "errors": [...]}, !ok); !ok without data when no
  /// rehearsal domain is configured, no controller reads recipes there (nothing sent) or none answered.
  virtual ActionResult rehearse(const std::string& task_id, const std::string& recipe_json,
                                const std::string& submitter) = 0;
  /// The rehearsal cell the console starts on demand: data = RehearsalLink::cell_status(); !ok without a
  /// rehearsal domain.
  virtual ActionResult rehearsal_cell() = 0;
  /// Asks the world model about the cell's revisions (rigger/world/cell_request; the node fills in the
  /// client and request ids): data = {"code", "cell_revision", "result": <result_json parsed>}, also when
  /// it refused (!ok, message = its reason); !ok without data when no world model answered.
  virtual ActionResult cell_request(const world_protocol::CellRequest& request) = 0;
  /// The STEP models the cell's running revision pins, as the world model published them
  /// (rigger/world/cell_model): `sha256` empty, data = [{"name", "sha256", "bytes"}] by name; else that
  /// model, data = {"name", "sha256", "step": <binary string>}, !ok when the cell has none of it.
  virtual ActionResult cell_models(const std::string& sha256) = 0;
};

/// What the console reads on the rehearsal domain (RehearsalLink), apart from the cell's: the HTTP side
/// serves it as /api/rehearsal/state and /api/rehearsal/events.
struct RehearsalFeed {
  std::uint32_t domain_id = 0;
  ConsoleState& state;
  EventLog& events;
  std::atomic<int>& watchers;  ///< open /api/rehearsal/events streams: the started cell is not idle
};

/// Where the Planner sends a STEP file to import (its body's limit is max_import_bytes, not max_body_bytes).
inline constexpr const char* kImportPath = "/api/planner/import";

struct HttpConfig {
  std::string address = "127.0.0.1";
  int port = 8080;
  std::string web_dir;                ///< the static pages (index.html, *.js) and node_modules/
  std::string tls_cert, tls_key;      ///< both set: HTTPS
  std::size_t max_body_bytes = 4U * 1024U * 1024U;
  std::chrono::milliseconds confirm_timeout{5000};
  std::string audit_log;              ///< JSON lines of every action; empty: log only
  std::size_t max_import_bytes = 64U * 1024U * 1024U;  ///< a STEP file sent to POST /api/planner/import
  int max_streams = 100;              ///< live (SSE) streams at once; each holds a worker thread
  /// Worker threads besides the streams': the requests of the pages always find one free.
  static constexpr int kRequestThreads = 16;
  std::string config_file;            ///< named in configuration errors
};

/// The HTTP server. start() binds and serves on its own thread; stop() ends it and every stream.
class HttpApi {
 public:
  /// `rehearsal`: the rehearsal cell's side, or none (POST /api/planner/rehearse then answers 409).
  /// `runs`: the plots of past runs, or none (GET /api/runs then answers 404).
  HttpApi(HttpConfig config, Users users, ConsoleState& state, EventLog& events, EventLog& plots, Backend& backend,
          SkillCatalog& skills, Logger log, std::optional<RehearsalFeed> rehearsal = std::nullopt,
          const RunArchive* runs = nullptr);
  ~HttpApi();
  HttpApi(const HttpApi&) = delete;
  HttpApi& operator=(const HttpApi&) = delete;

  /// Binds the address and port (port 0: any free one) and serves. @throws ConfigError when it cannot.
  void start();
  void stop();
  /// The bound port (after start()).
  int port() const { return port_; }
  bool tls() const { return !config_.tls_cert.empty(); }
  /// Journals what the console did by itself (user "console", role "system"), `who` having caused it
  /// ("console" when nobody did). Any thread.
  void audit_system(const std::string& action, const std::string& target, const std::string& result,
                    const std::string& who);

 private:
  struct Pending {
    std::string user;
    std::string kind;  ///< "publish", "resume" or "cell"
    std::string task_id;  ///< for "cell": "apply" or "rollback <revision>"
    std::string payload;  ///< the recipe text for publish; the cell request for "cell"
    std::chrono::steady_clock::time_point deadline;
  };
  // The routes: routes() registers the table of method + path -> handler (http_api.cpp); each handler
  // is one member function, grouped by area in http_read_routes.cpp, http_planner_routes.cpp and
  // http_command_routes.cpp.
  using Handler = void (HttpApi::*)(const httplib::Request&, httplib::Response&);
  void routes();
  void audit(const User& user, const std::string& action, const std::string& target, const std::string& result);
  void append_audit(const nlohmann::json& line);
  std::string new_confirmation(Pending p);
  // Who is asking, and may they? Sends 401/403 and returns nullopt when not. Only the event streams
  // take the token from the query (?token=) or the rigger_token cookie: EventSource cannot set headers.
  std::optional<User> who(const httplib::Request& req, httplib::Response& res, Role needed, bool stream = false);
  // The request body as a JSON object, parsed within bounds; sends 400 and returns nullopt otherwise.
  std::optional<nlohmann::json> body(const httplib::Request& req, httplib::Response& res);

  // Reads.
  void get_me(const httplib::Request& req, httplib::Response& res);
  void get_state(const httplib::Request& req, httplib::Response& res);
  void get_events(const httplib::Request& req, httplib::Response& res);
  void get_plots_stream(const httplib::Request& req, httplib::Response& res);
  void get_plots(const httplib::Request& req, httplib::Response& res);
  void get_world_entities(const httplib::Request& req, httplib::Response& res);
  void get_runs(const httplib::Request& req, httplib::Response& res);
  void get_run_plots(const httplib::Request& req, httplib::Response& res);
  void get_run_cell(const httplib::Request& req, httplib::Response& res);
  /// A kept run's rows of one kind (RunArchive::rows or cell_rows), or 404.
  void send_run_rows(const httplib::Request& req, httplib::Response& res,
                     std::optional<std::string> (RunArchive::*read)(const std::string&) const);
  void get_journal(const httplib::Request& req, httplib::Response& res);
  void get_world_entity(const httplib::Request& req, httplib::Response& res);
  void get_cad_model(const httplib::Request& req, httplib::Response& res);
  void get_cad_features(const httplib::Request& req, httplib::Response& res);
  void get_cad_parts(const httplib::Request& req, httplib::Response& res);
  void cad_read(const httplib::Request& req, httplib::Response& res, const char* kind, const char* what);
  void get_skills(const httplib::Request& req, httplib::Response& res);
  // The planner and the rehearsal cell.
  void post_planner_validate(const httplib::Request& req, httplib::Response& res);
  void post_planner_screws(const httplib::Request& req, httplib::Response& res);
  void post_planner_frame(const httplib::Request& req, httplib::Response& res);
  void post_planner_place(const httplib::Request& req, httplib::Response& res);
  void post_planner_import(const httplib::Request& req, httplib::Response& res);
  void post_planner_import_node(const httplib::Request& req, httplib::Response& res);
  void get_planner_cell_models(const httplib::Request& req, httplib::Response& res);
  void post_planner_declare(const httplib::Request& req, httplib::Response& res);
  void post_planner_add(const httplib::Request& req, httplib::Response& res);
  void post_planner_replace(const httplib::Request& req, httplib::Response& res);
  bool refused_while_tasks_run(const User& user, const std::string& what, const std::string& doing,
                               const httplib::Request& req, httplib::Response& res);
  void get_rehearsal_state(const httplib::Request& req, httplib::Response& res);
  void get_rehearsal_events(const httplib::Request& req, httplib::Response& res);
  void post_planner_rehearse(const httplib::Request& req, httplib::Response& res);
  void get_rehearsal_cell(const httplib::Request& req, httplib::Response& res);
  // Commands.
  void post_recipe(const httplib::Request& req, httplib::Response& res);
  void post_task_resume(const httplib::Request& req, httplib::Response& res);
  void post_confirm(const httplib::Request& req, httplib::Response& res);
  void post_task_cancel(const httplib::Request& req, httplib::Response& res);
  void post_task_pause(const httplib::Request& req, httplib::Response& res);
  void post_task_stop(const httplib::Request& req, httplib::Response& res);
  void task_command(const httplib::Request& req, httplib::Response& res, const std::string& kind, Role needed);
  void post_prompt_answer(const httplib::Request& req, httplib::Response& res);
  // Cell revisions (http_cell_routes.cpp).
  void get_cell(const httplib::Request& req, httplib::Response& res);
  void get_cell_history(const httplib::Request& req, httplib::Response& res);
  void post_cell_revision(const httplib::Request& req, httplib::Response& res);
  /// The first step of a cell revision (`payload`: {"op", "cell_json" or "revision", "comment"}): the
  /// world model's dry run, then 202 with a confirmation id, what would change and `extra`'s keys; or
  /// the world model's refusal. Audited as "select cell <target>".
  void select_cell_revision(const User& user, const nlohmann::json& payload, const std::string& target,
                            const httplib::Request& req, httplib::Response& res,
                            nlohmann::json extra = nlohmann::json::object());
  /// Applies a confirmed cell revision (`p` from POST /api/confirm).
  void confirm_cell(const User& user, const Pending& p, const httplib::Request& req, httplib::Response& res);
  /// The world model's running cell revision: its number and document (bounded parse).
  struct RunningCell {
    std::uint64_t revision = 0;
    nlohmann::json document;
  };
  /// The running cell, or none after answering why (the world model's refusal, or 503 when the document
  /// does not parse).
  std::optional<RunningCell> running_cell(const httplib::Request& req, httplib::Response& res);
  /// Sends the world model's answer to a cell request: 200 with its result, or its refusal as an error.
  void send_cell_answer(const httplib::Request& req, httplib::Response& res, const ActionResult& r);
  /// 409: a revision pins an imported file the console no longer keeps.
  void imported_file_gone(const httplib::Request& req, httplib::Response& res, const std::string& sha256);

  HttpConfig config_;
  StreamSlots streams_;
  Users users_;
  ConsoleState& state_;
  EventLog& events_;
  EventLog& plots_;
  Backend& backend_;
  SkillCatalog& skills_;
  Logger log_;
  std::optional<RehearsalFeed> rehearsal_;
  ImportedModels imports_;  ///< STEP files imported in the Planner, until a revision adds them
  const RunArchive* runs_;
  std::unique_ptr<httplib::Server> server_;
  std::thread thread_;
  int port_ = 0;
  std::mutex audit_mutex_;
  std::mutex pending_mutex_;
  std::map<std::string, Pending> pending_;
};

}  // namespace rigger::console
