// `riggerctl sim …`: fault injection into the simulated cell (rigger/sim/control, answered on
// rigger/sim/event), to see for yourself what rigger does when something breaks. A real cell has no
// simulator: the command then finds no reader and says so.
#include <unistd.h>

#include <cstdio>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "commands.hpp"
#include "rigger/base/text.hpp"
#include "rigger/base/time.hpp"
#include "rigger/dds/conversions.hpp"
#include "rigger/dds/event_loop.hpp"
#include "rigger/dds/pubsub.hpp"
#include "rigger/protocol/sim.hpp"

namespace rigger::ctl {
namespace {

// cell_sim's fault-injection topics (services/cell_sim/src/cell_sim_node.hpp).
constexpr int kExitRefused = 1;
constexpr int kExitNoSimulator = 3;

struct SimRequest {
  rigger_sim_SimControlKind kind = rigger_sim_SIM_RESET;
  std::string switch_state = "on";  // on|off, for plc-link and estop
  std::string holding_force;        // a number in N, or "default"
  std::vector<double> force_n;      // load-force: fx fy fz
  double timeout_s = 5;
};

/// "what was asked" for the answer line, e.g. "plc-link off".
std::string describe(const SimRequest& r) {
  switch (r.kind) {
    case rigger_sim_SIM_PLC_LINK: return "plc-link " + r.switch_state;
    case rigger_sim_SIM_ESTOP: return "estop " + r.switch_state;
    case rigger_sim_SIM_SET_HOLDING_FORCE: return "holding-force " + r.holding_force;
    case rigger_sim_SIM_SET_LOAD_FORCE:
      return "load-force " + number_text(r.force_n[0]) + " " + number_text(r.force_n[1]) + " " +
             number_text(r.force_n[2]) + " N";
    default: return "reset";
  }
}

int run(const CommonOptions& common, const SimRequest& request) {
  rigger_sim_SimControl c{};
  c.kind = request.kind;
  c.on = request.switch_state == "on";
  if (request.kind == rigger_sim_SIM_SET_HOLDING_FORCE) {
    if (request.holding_force == "default") {
      c.value = -1.0;  // the cell's configured holding force
    } else {
      std::size_t used = 0;
      try {
        c.value = std::stod(request.holding_force, &used);
      } catch (const std::exception&) {
        used = 0;
      }
      if (used == 0 || used != request.holding_force.size() || c.value < 0.0) {
        std::fprintf(stderr, "riggerctl: holding-force: expected a force in N (>= 0) or \"default\", got \"%s\"\n",
                     request.holding_force.c_str());
        return 2;
      }
    }
  }
  if (request.kind == rigger_sim_SIM_SET_LOAD_FORCE)
    c.vector = dds::to_wire_vector(Eigen::Vector3d(request.force_n[0], request.force_n[1], request.force_n[2]));

  dds::Participant participant(common.domain);
  dds::EventLoop loop(participant);
  dds::Writer<rigger_sim_SimControl> controls(participant, protocol::sim::kControl);
  dds::Reader<rigger_sim_SimEvent> events(participant, protocol::sim::kEvent);
  const auto timeout = from_seconds(request.timeout_s);
  // The answer comes on the events topic: wait until the simulator reads ours and writes to us.
  const bool matched =
      controls.wait_for_readers(1, timeout) &&
      events.wait_for_writers(1, timeout);
  if (!matched) {
    std::fprintf(stderr, "riggerctl: no simulated cell on %s (waited %.1f s); sim works with cell_sim only\n",
                 dds::describe_domain(common.domain).c_str(), request.timeout_s);
    return kExitNoSimulator;
  }
  const std::string source = "riggerctl-" + std::to_string(::getpid());
  std::optional<std::pair<bool, std::string>> answer;
  loop.on_data(events, [&] {
    events.take([&](const rigger_sim_SimEvent& e, const dds_sample_info_t&) {
      if (dds::to_string(e.control_source) == source && e.control_seq == 1)
        answer = std::make_pair(static_cast<bool>(e.accepted), dds::to_string(e.message));
    });
  });
  c.header.stamp = dds::wire_now();
  c.seq = 1;  // one control per process; the source tells processes apart
  c.source = dds::wire_string(source);
  if (const dds_return_t rc = controls.write(c); rc != DDS_RETCODE_OK) {
    std::fprintf(stderr, "riggerctl: sending the control failed: %s\n", dds_strretcode(rc));
    return kExitRefused;
  }
  if (!loop.run_until([&] { return answer.has_value(); }, timeout)) {
    std::fprintf(stderr, "riggerctl: the simulator did not answer %s within %.1f s\n", describe(request).c_str(),
                 request.timeout_s);
    return kExitRefused;
  }
  if (!answer->first) {
    std::fprintf(stderr, "riggerctl: the simulator refused %s: %s\n", describe(request).c_str(),
                 answer->second.c_str());
    return kExitRefused;
  }
  std::printf("sim %s: %s\n", describe(request).c_str(), answer->second.empty() ? "done" : answer->second.c_str());
  return 0;
}

}  // namespace

void add_sim_command(CLI::App& app, const CommonOptions& common, int& exit_code) {
  auto request = std::make_shared<SimRequest>();
  auto* sim = app.add_subcommand("sim", "Inject a fault into the simulated cell (cell_sim only)");
  sim->require_subcommand(1);
  sim->add_option("--timeout", request->timeout_s, "Seconds to wait for the simulator and its answer (default 5)");
  const auto on_off = [&](CLI::App* cmd) {
    cmd->add_option("state", request->switch_state, "on or off")->required()->check(CLI::IsMember({"on", "off"}));
  };
  auto* link = sim->add_subcommand("plc-link", "off: cut the crane PLC's Modbus link (every connection closes); on: restore it");
  on_off(link);
  link->callback([request] { request->kind = rigger_sim_SIM_PLC_LINK; });
  auto* estop = sim->add_subcommand("estop", "on: press the cell's e-stop (crane and robot stop); off: release it");
  on_off(estop);
  estop->callback([request] { request->kind = rigger_sim_SIM_ESTOP; });
  auto* holding = sim->add_subcommand("holding-force", "Set the magnet's holding force in N (\"default\": the cell's)");
  holding->add_option("newtons", request->holding_force, "N, or default")->required();
  holding->callback([request] { request->kind = rigger_sim_SIM_SET_HOLDING_FORCE; });
  auto* load = sim->add_subcommand("load-force", "Push the load's centre with a constant force, world frame, N (0 0 0 removes it)");
  load->add_option("force", request->force_n, "FX FY FZ in N")->required()->expected(3);
  load->callback([request] { request->kind = rigger_sim_SIM_SET_LOAD_FORCE; });
  auto* reset = sim->add_subcommand("reset", "Put the physics back to its initial state, every injected fault removed");
  reset->callback([request] { request->kind = rigger_sim_SIM_RESET; });
  // The leaf's callback runs first (it sets the kind), then this one sends.
  sim->callback([&common, &exit_code, request] { exit_code = run(common, *request); });
}

}  // namespace rigger::ctl
