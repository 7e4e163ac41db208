// `riggerctl crane reset`: acknowledge a latched crane fault (a PLC heartbeat timeout after a cut cable,
// a released e-stop) by CRANE_RESET on rigger/crane/control, and say whether the crane reports it cleared.
// A reset clears a fault only when its cause is gone: with the e-stop still pressed, the PLC keeps it.
// The gateway logs every control with its source; the reset moves nothing by itself (the crane takes
// velocities again only from a fresh, in-date command stream).
#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <memory>
#include <optional>
#include <string>

#include "commands.hpp"
#include "rigger/base/time.hpp"
#include "rigger/dds/conversions.hpp"
#include "rigger/dds/event_loop.hpp"
#include "rigger/dds/pubsub.hpp"
#include "rigger/protocol/crane.hpp"

namespace rigger::ctl {
namespace {

constexpr int kExitStillFaulted = 1;
constexpr int kExitNoGateway = 3;

struct CraneRequest {
  double timeout_s = 5.0;
};

/// What riggerctl reads of one crane state.
struct Seen {
  WallTime stamp{};
  bool fault = false, estop = false, link_ok = false;
  std::uint16_t fault_code = 0;
  std::string fault_text;
};

std::string describe(const Seen& s) {
  if (!s.link_ok) return "no link to the PLC (" + (s.fault_text.empty() ? std::string("link down") : s.fault_text) + ")";
  if (!s.fault) return "no fault";
  std::string out = "fault " + std::to_string(s.fault_code);
  if (!s.fault_text.empty()) out += " (" + s.fault_text + ")";
  if (s.estop) out += ", e-stop latched";
  return out;
}

int reset(const CommonOptions& common, const CraneRequest& request) {
  dds::Participant participant(common.domain);
  dds::EventLoop loop(participant);
  dds::Writer<rigger_crane_CraneControl> control(participant, protocol::crane::kControl);
  dds::Reader<rigger_crane_CraneState> states(participant, protocol::crane::kState);
  const auto timeout = from_seconds(request.timeout_s);
  std::optional<Seen> latest;
  loop.on_data(states, [&] {
    states.take([&](const rigger_crane_CraneState& s, const dds_sample_info_t&) {
      Seen v;
      v.stamp = dds::to_domain(s.header.stamp);
      v.fault = s.fault;
      v.estop = s.estop;
      v.link_ok = s.link_ok;
      v.fault_code = s.fault_code;
      v.fault_text = dds::to_string(s.fault_text);
      latest = v;
    });
  });
  if (!control.wait_for_readers(1, timeout) || !loop.run_until([&] { return latest.has_value(); }, timeout)) {
    std::fprintf(stderr, "riggerctl crane reset: no crane gateway on %s (no reader of %s or no %s within %.1f s): "
                 "nothing was sent\n",
                 dds::describe_domain(common.domain).c_str(), protocol::crane::kControl.name,
                 protocol::crane::kState.name, request.timeout_s);
    return kExitNoGateway;
  }
  const Seen before = *latest;
  const char* user = std::getenv("USER");
  const std::string source = std::string("riggerctl:") + (user != nullptr && *user ? user : std::to_string(getuid()));
  rigger_crane_CraneControl c{};
  c.header.stamp = dds::wire_now();
  c.seq = 1;  // one control per process; the source tells them apart in the gateway's log
  c.kind = rigger_crane_CRANE_RESET;
  c.source = dds::wire_string(source);
  const WallTime sent = std::chrono::system_clock::now();
  if (const dds_return_t rc = control.write(c); rc != DDS_RETCODE_OK) {
    std::fprintf(stderr, "riggerctl crane reset: writing the reset failed: %s\n", dds_strretcode(rc));
    return kExitStillFaulted;
  }
  // The gateway pulses the PLC's reset bit for a few cycles; the answer is a state published after it.
  const bool cleared = loop.run_until([&] { return latest->stamp > sent && latest->link_ok && !latest->fault; }, timeout);
  if (!cleared) {
    std::fprintf(stderr,
                 "riggerctl crane reset: the crane still reports %s %.1f s after the reset (was: %s); the PLC keeps a "
                 "fault while its cause is there: release the e-stop, restore the PLC link, then reset again\n",
                 describe(*latest).c_str(), request.timeout_s, describe(before).c_str());
    return kExitStillFaulted;
  }
  std::printf("crane reset by %s: %s (was: %s)\n", source.c_str(), describe(*latest).c_str(), describe(before).c_str());
  return 0;
}

}  // namespace

void add_crane_command(CLI::App& app, const CommonOptions& common, int& exit_code) {
  auto* crane = app.add_subcommand("crane", "The crane through its gateway");
  crane->require_subcommand(1);
  auto request = std::make_shared<CraneRequest>();
  auto* cmd = crane->add_subcommand(
      "reset", "Acknowledge a latched crane fault (CRANE_RESET) and wait until the crane reports it cleared");
  cmd->add_option("--timeout", request->timeout_s, "seconds to wait for the gateway and for the fault to clear")
      ->check(CLI::Range(0.1, 600.0));
  cmd->callback([request, &common, &exit_code] { exit_code = reset(common, *request); });
}

}  // namespace rigger::ctl
