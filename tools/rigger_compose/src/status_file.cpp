#include "rigger/compose/status_file.hpp"

#include <cstdio>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "rigger/base/bounded_json.hpp"

namespace rigger::compose {
namespace {

std::int64_t to_unix_ms(Clock::time_point t, Clock::time_point steady_now, std::int64_t unix_now) {
  return unix_now - std::chrono::duration_cast<std::chrono::milliseconds>(steady_now - t).count();
}

}  // namespace

const ServiceStatusEntry* SupervisorStatus::find(const std::string& name) const {
  for (const auto& s : services)
    if (s.name == name) return &s;
  return nullptr;
}

std::int64_t unix_now_ms() {
  return std::chrono::duration_cast<std::chrono::milliseconds>(std::chrono::system_clock::now().time_since_epoch())
      .count();
}

SupervisorStatus make_status(const Supervision& supervision, Clock::time_point steady_now, std::int64_t unix_now) {
  SupervisorStatus out;
  out.phase = to_string(supervision.phase());
  out.failure = supervision.failure();
  out.started_unix_ms = to_unix_ms(supervision.began(), steady_now, unix_now);
  out.updated_unix_ms = unix_now;
  for (const auto& s : supervision.services()) {
    ServiceStatusEntry e;
    e.name = s.name();
    e.host = s.def->host;
    e.local = s.local;
    e.state = to_string(s.state);
    if (!s.local && s.remote_ready) e.state = "remote-ready";
    e.pid = s.pid;
    e.restarts = s.restarts;
    if (s.local && s.state != ServiceState::kWaiting) e.started_unix_ms = to_unix_ms(s.started, steady_now, unix_now);
    if (s.ready_at) e.ready_unix_ms = to_unix_ms(*s.ready_at, steady_now, unix_now);
    if (s.state == ServiceState::kBackoff && s.deadline)
      e.next_start_unix_ms = to_unix_ms(*s.deadline, steady_now, unix_now);
    e.last_exit = s.last_exit;
    out.services.push_back(e);
  }
  return out;
}

std::string to_json_text(const SupervisorStatus& st) {
  nlohmann::json services = nlohmann::json::array();
  for (const auto& s : st.services) {
    services.push_back({{"name", s.name},
                        {"host", s.host},
                        {"local", s.local},
                        {"state", s.state},
                        {"pid", s.pid},
                        {"restarts", s.restarts},
                        {"started_unix_ms", s.started_unix_ms},
                        {"ready_unix_ms", s.ready_unix_ms},
                        {"next_start_unix_ms", s.next_start_unix_ms},
                        {"last_exit", s.last_exit}});
  }
  const nlohmann::json j{{"supervisor_pid", st.supervisor_pid},
                         {"domain", st.domain},
                         {"compose_file", st.compose_file},
                         {"log_dir", st.log_dir},
                         {"phase", st.phase},
                         {"failure", st.failure},
                         {"started_unix_ms", st.started_unix_ms},
                         {"updated_unix_ms", st.updated_unix_ms},
                         {"services", services}};
  return j.dump(2) + "\n";
}

SupervisorStatus status_from_json_text(const std::string& text) {
  try {
    auto parsed = parse_json_bounded(text, JsonLimits{1024U * 1024U, 8});
    if (!parsed.ok()) throw std::runtime_error("malformed status file: " + parsed.error->to_string());
    const auto& j = parsed.value;
    SupervisorStatus st;
    st.supervisor_pid = j.at("supervisor_pid").get<int>();
    st.domain = j.at("domain").get<std::uint32_t>();
    st.compose_file = j.at("compose_file").get<std::string>();
    st.log_dir = j.at("log_dir").get<std::string>();
    st.phase = j.at("phase").get<std::string>();
    st.failure = j.at("failure").get<std::string>();
    st.started_unix_ms = j.at("started_unix_ms").get<std::int64_t>();
    st.updated_unix_ms = j.at("updated_unix_ms").get<std::int64_t>();
    for (const auto& s : j.at("services")) {
      ServiceStatusEntry e;
      e.name = s.at("name").get<std::string>();
      e.host = s.at("host").get<std::string>();
      e.local = s.at("local").get<bool>();
      e.state = s.at("state").get<std::string>();
      e.pid = s.at("pid").get<int>();
      e.restarts = s.at("restarts").get<int>();
      e.started_unix_ms = s.at("started_unix_ms").get<std::int64_t>();
      e.ready_unix_ms = s.at("ready_unix_ms").get<std::int64_t>();
      e.next_start_unix_ms = s.at("next_start_unix_ms").get<std::int64_t>();
      e.last_exit = s.at("last_exit").get<std::string>();
      st.services.push_back(e);
    }
    return st;
  } catch (const nlohmann::json::exception& e) {
    throw std::runtime_error(std::string("malformed status file: ") + e.what());
  }
}

bool write_status_file(const std::string& path, const SupervisorStatus& status) {
  const std::string tmp = path + ".tmp";
  {
    std::ofstream out(tmp, std::ios::trunc);
    if (!out) return false;
    out << to_json_text(status);
    if (!out.flush()) return false;
  }
  return std::rename(tmp.c_str(), path.c_str()) == 0;
}

std::optional<SupervisorStatus> read_status_file(const std::string& path) {
  std::ifstream in(path);
  if (!in) return std::nullopt;
  std::stringstream ss;
  ss << in.rdbuf();
  try {
    return status_from_json_text(ss.str());
  } catch (const std::runtime_error&) {
    return std::nullopt;
  }
}

}  // namespace rigger::compose
