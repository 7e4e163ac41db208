#include "rigger/console/settings.hpp"
#include "rigger/base/install.hpp"

namespace rigger::console {

const SettingsTable<ConsoleSettings>& console_settings() {
  using S = ConsoleSettings;
  const auto rehearsal = [](Setting<S> s) { return nested("rehearsal", std::move(s)); };
  static const SettingsTable<S> table{
      setting<S>("address", "127.0.0.1", &S::address,
                 "the address to listen on (only this host by default; `0.0.0.0` for every interface — then use "
                 "TLS)"),
      setting<S>("port", 8080, {0, 65535}, &S::port, "0: any free port (printed at start)"),
      setting<S>("users_file", "/var/tmp/rigger/console-users.json", &S::users_file,
                 "users and token hashes ([console.md](console.md)); missing or malformed: the console does not "
                 "start"),
      setting<S>("audit_log", "/var/tmp/rigger/console-audit.log", &S::audit_log,
                 "one JSON line per action: time, user, role, action, target, result; `\"\"`: none"),
      setting<S>("runs_dir", "/var/tmp/rigger/console-runs", &S::runs_dir,
                 "where the plots of each task run are kept, so a finished run can be replayed after a restart "
                 "([console.md](console.md#replay)); `\"\"`: not kept"),
      setting<S>("max_runs", 200u, {1u, 100000u}, &S::max_runs,
                 "how many runs `runs_dir` keeps; the oldest finished run is removed first"),
      setting<S>("tls_cert", "", &S::tls_cert,
                 "a PEM certificate: with `tls_key`, the console speaks HTTPS only; give both or neither"),
      setting<S>("tls_key", "", &S::tls_key, "the PEM key of `tls_cert`"),
      setting<S>("confirm_timeout_s", 5.0, {0.5, 120.0}, &S::confirm_timeout,
                 "how long a selected publish/resume waits for its confirmation"),
      setting<S>("max_body_bytes", 4u * 1024u * 1024u, {1024u, 100u * 1024u * 1024u}, &S::max_body_bytes,
                 "larger request bodies are refused with 413 before they are read"),
      setting<S>("max_import_mib", 64.0, {0.001, 1024.0},
                 [](S& s, double mib) { s.max_import_bytes = static_cast<std::size_t>(mib * (1 << 20)); },
                 "a STEP file sent to the Planner's Import (`POST /api/planner/import`); larger ones are refused "
                 "with 413 before they are read. The CAD service has its own bound, `max_file_mib`"),
      setting<S>("max_streams", 100, {1, 1000}, &S::max_streams,
                 "live streams (a page's events, plots or rehearsal; each browser tab opens one or two) served at "
                 "once, each on an HTTP worker thread of its own; one more is refused with 503 and `Retry-After`, "
                 "so that the pages' requests always find a free worker"),
      setting<S>("plot_rate_hz", 20.0, {1.0, 100.0}, &S::plot_rate_hz,
                 "plot rows per second while sensor samples come (the average force over the interval; the "
                 "latest state of the others)"),
      setting<S>("query_timeout_s", 3.0, {0.1, 60.0}, &S::query_timeout,
                 "how long a journal, world or CAD query waits for its answer"),
      own_setting<S>(
          "rehearsal_domain", "integer", "none", "[0, 230]",
          [](const Config& config, const std::string& key, S& s) {
            if (config.has(key))
              s.rehearsal_domain = static_cast<std::uint32_t>(config.get_in_range<int>(key, 0, 0, 230));
          },
          "the DDS domain of the rehearsal cell, where the Planner's Rehearse runs a recipe first "
          "([console.md](console.md#rehearsal)); none: no rehearsal. Must differ from the console's own domain"),
      rehearsal(setting<S>(
          "start", std::vector<std::string>{}, &S::rehearsal_start,
          "the command (program and arguments) that brings up the rehearsal cell, in the foreground, when a "
          "Rehearse finds no controller on `rehearsal_domain`; it runs in the folder of this file with "
          "`RIGGER_DOMAIN` set to `rehearsal_domain`, a program without a `/` is looked up beside the console, "
          "then in `PATH` ([console.md](console.md#the-rehearsal-cell-on-demand)); `[]`: the rehearsal cell is started by hand")),
      rehearsal(setting<S>("env", std::vector<std::string>{}, &S::rehearsal_env,
                           "`NAME=value` entries added to the start command's environment")),
      rehearsal(own_setting<S>(
          "cell_folder", "path", "none", "",
          [](const Config& config, const std::string& key, S& s) {
            if (config.has(key)) s.rehearsal_cell_folder = config_path(config, key).string();
          },
          "the folder of the cell file the rehearsal cell's services are configured with (relative to this "
          "file): where the models a revision does not pin by sha256 are read when the console starts the "
          "rehearsal cell on the cell's revision (`RIGGER_CELL_FILE`, "
          "[console.md](console.md#the-rehearsal-cell-on-demand)); none: only a revision whose models are all "
          "pinned is started on")),
      rehearsal(setting<S>("log_file", "/var/tmp/rigger/console-rehearsal-cell.log", &S::rehearsal_log,
                           "where the start command's output is appended (the page names it when a start "
                           "fails); its folder is made")),
      rehearsal(setting<S>("start_timeout_s", 120.0, {1.0, 3600.0}, &S::rehearsal_start_timeout,
                           "how long the start may take until a task controller reads recipes and a world model "
                           "answers cell requests on the rehearsal domain; then it is stopped and the rehearsal "
                           "refused")),
      rehearsal(setting<S>("idle_stop_s", 120.0, {1.0, 86400.0}, &S::rehearsal_idle_stop,
                           "the started cell is stopped after so long without a rehearsal running or a page "
                           "watching one")),
      rehearsal(setting<S>("stop_timeout_s", 30.0, {1.0, 600.0}, &S::rehearsal_stop_timeout,
                           "SIGTERM to the start command, then SIGKILL to its process group after so long")),
      path_setting<S>(
          "web_dir", "web", [](S& s, const std::filesystem::path& p) { s.web_dir = p.string(); },
          "the pages and their `node_modules/`: relative to this file, then to the data folder (the "
          "build tree links it to `services/console/web`)"),
  };
  return table;
}

ConsoleSettings read_console_settings(const Config& config) {
  ConsoleSettings s = read_settings(config, console_settings());
  if (s.tls_cert.empty() != s.tls_key.empty())
    throw ConfigError(config.file(), "/tls_key", "give both tls_cert and tls_key, or neither");
  if (!s.rehearsal_start.empty() && !s.rehearsal_domain)
    throw ConfigError(config.file(), "/rehearsal/start", "a start command needs rehearsal_domain, the domain it runs on");
  for (std::size_t i = 0; i < s.rehearsal_env.size(); ++i) {
    const auto eq = s.rehearsal_env[i].find('=');
    if (eq == std::string::npos || eq == 0)
      throw ConfigError(config.file(), "/rehearsal/env/" + std::to_string(i),
                        "expected NAME=value, got \"" + s.rehearsal_env[i] + "\"");
  }
  return s;
}

}  // namespace rigger::console
