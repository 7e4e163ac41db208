// `riggerctl estop`: the software safe stop (rigger/safety/stop) from the command line, and its reset.
// It is a supervisor's stop on top of the robot controller's and the crane PLC's hardware e-stops,
// never a replacement for them: DDS and Linux are not a safety-rated channel (docs/safety.md).
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <string>
#include <vector>

#include "commands.hpp"
#include "quiet_matching.hpp"
#include "rigger/base/time.hpp"
#include "rigger/safety/safe_stop.hpp"

namespace rigger::ctl {
namespace {

constexpr int kExitFailed = 1;
constexpr int kExitNoDevice = 3;

struct EstopRequest {
  std::vector<std::string> resources;  // empty: every stoppable resource
  bool reset = false;
  std::string reason;
  double timeout_s = 5.0;
};

std::string joined(const std::vector<std::string>& words) {
  std::string out;
  for (const auto& w : words) out += (out.empty() ? "" : ", ") + w;
  return out;
}

int run(const CommonOptions& common, EstopRequest request) {
  const auto& known = safety::stoppable_resources();
  if (request.resources.empty()) request.resources = known;
  for (const auto& r : request.resources) {
    if (std::find(known.begin(), known.end(), r) == known.end()) {
      std::fprintf(stderr, "riggerctl estop: unknown resource '%s' (expected one of: %s)\n", r.c_str(),
                   joined(known).c_str());
      return 2;
    }
  }
  const std::string source = riggerctl_source();
  const std::string reason = request.reason.empty() ? (request.reset ? "reset" : "estop from riggerctl") : request.reason;

  dds::Participant participant(common.domain);
  safety::SafeStopWriter stops(participant);
  if (!stops.writer().wait_for_readers(1, from_seconds(request.timeout_s))) {
    std::fprintf(stderr,
                 "riggerctl estop: no device listens on %s on domain %u within %.1f s: nothing was %s "
                 "(the hardware e-stops are the safety function: use them)\n",
                 protocol::safety::kStop.name, common.domain, request.timeout_s, request.reset ? "reset" : "stopped");
    return kExitNoDevice;
  }
  // The first device matched; the others may be a discovery round behind (another host, a tool just
  // started). The samples are latched but live only as long as this writer, so a device matched later
  // than our exit would never see them: wait until no new device has matched for 0.6 s.
  wait_for_quiet_matching(stops.writer().handle(), DDS_PUBLICATION_MATCHED_STATUS,
                               [&] { return stops.writer().matched_readers(); }, std::chrono::milliseconds(600),
                               from_seconds(request.timeout_s));
  for (const auto& r : request.resources) {
    if (const auto rc = stops.command(r, !request.reset, source, reason); rc != DDS_RETCODE_OK) {
      std::fprintf(stderr, "riggerctl estop: writing the %s of %s failed (DDS return code %d)\n",
                   request.reset ? "reset" : "stop", r.c_str(), static_cast<int>(rc));
      return kExitFailed;
    }
  }
  // Every matched device has the samples (reliable): only then is the stop in their hands.
  if (dds_wait_for_acks(stops.writer().handle(), DDS_SECS(static_cast<int64_t>(request.timeout_s))) != DDS_RETCODE_OK) {
    std::fprintf(stderr, "riggerctl estop: not every device acknowledged within %.1f s\n", request.timeout_s);
    return kExitFailed;
  }
  dds_publication_matched_status_t matched{};
  dds_get_publication_matched_status(stops.writer().handle(), &matched);
  std::printf("%s %s (%u device%s acknowledged; by %s: %s)\n", request.reset ? "safe stop reset:" : "safe stop:",
              joined(request.resources).c_str(), matched.current_count, matched.current_count == 1 ? "" : "s",
              source.c_str(), reason.c_str());
  if (!request.reset) {
    std::string named;
    if (request.resources.size() != known.size())
      for (const auto& r : request.resources) named += " " + r;
    std::printf("the stop is latched: `riggerctl estop --reset%s` when the cell is safe again\n", named.c_str());
  }
  return 0;
}

}  // namespace

std::string riggerctl_source() {
  const char* user = std::getenv("USER");
  return std::string("riggerctl:") + (user != nullptr && *user ? user : std::to_string(getuid()));
}

void add_estop_command(CLI::App& app, const CommonOptions& common, int& exit_code) {
  auto* cmd = app.add_subcommand("estop",
                                 "Software safe stop of the cell's devices (latched until --reset); the hardware "
                                 "e-stops remain the safety function.");
  auto request = std::make_shared<EstopRequest>();
  cmd->add_option("RESOURCE", request->resources, "robot, crane, gripper, admittance (default: all)");
  cmd->add_flag("--reset", request->reset, "release the stop of these resources");
  cmd->add_option("--reason", request->reason, "why (shown by every device and in their logs)");
  cmd->add_option("--timeout", request->timeout_s, "seconds to wait for the devices");
  cmd->callback([request, &common, &exit_code] { exit_code = run(common, *request); });
}

}  // namespace rigger::ctl
