// riggerctl skills: the live executors and the skills and monitors they offer.
#include <chrono>
#include <cstdio>
#include <map>

#include <nlohmann/json.hpp>

#include "quiet_matching.hpp"
#include "rigger/base/bounded_json.hpp"
#include "rigger/base/time.hpp"
#include "rigger/dds/conversions.hpp"
#include "rigger/protocol/skill.hpp"
#include "task_support.hpp"

namespace rigger::ctl::tasks {
namespace {

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
}  // namespace

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

}  // namespace rigger::ctl::tasks
