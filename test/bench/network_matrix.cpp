// The echo round trip and the skill-event reaction latency over {loopback, two hosts} x {DDS Security off,
// on}, in one run, with each figure's ratio against loopback with security off (docs/deploy.md).
//
//   loopback   every process on this host, deploy/cyclonedds.xml (unicast discovery on lo)
//   two hosts  a lab of two network namespaces joined by a bridge (rigger::testing::Lab, deploy/lab-hosts),
//              deploy/cyclonedds-lab.xml (multicast discovery on eth0): host "controller" runs echo and
//              task_controller, host "executors" runs the two scripted executors and this process
//   secured    the same plus deploy/cyclonedds-secure.xml's <Security> (for two hosts, that section put
//              into the lab file, as docs/security.md tells a multi-host site to do), with a PKI made
//              for the run by deploy/security/make-pki; each process joins as its own identity
//
// Echo: the round trip of bench_dds_echo_security (echo_rtt.*) from this process to echo (across the
// bridge on two hosts). Reaction: the pattern and measurement of task_controller_live_bench
// (services/task_controller/bench/live_reaction.*): a monitor's FAILURE written on the executors' host
// -> the controller -> the sibling skill's SHUTDOWN taken by the skill's executor, on the executors' host
// too, so both hops cross the bridge; the journal as deployed (journal_sync normal). Clocks: one
// machine, one wall clock (namespaces share it). Left out, as warm-up: echo's first second, and the
// reaction's first --warmup trials (a task of their own, run before the measured one).
//
// The two-host rows need root (network namespaces); without it the bench says so and measures loopback
// only. The four setups run in turn, --rounds times, and each setup's samples are pooled over the
// rounds, so that a change of the machine's load falls on all of them alike. Progress goes to stderr,
// the processes' logs to build/test-logs/no-test-<pid>/<setup>-<round>/.
//
//   build/bench/bench_network_matrix [--trials 200] [--warmup 10] [--period-ms 10] [--seconds 3] [--rate 1000]
//                                    [--size 64] [--rounds 3]
#include <stdlib.h>
#include <unistd.h>

#include <cstdio>
#include <fstream>
#include <map>
#include <memory>
#include <sstream>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "bench_util.hpp"
#include "echo_rtt.hpp"
#include "live_reaction.hpp"
#include "rigger/testing/cell.hpp"
#include "rigger/testing/lab.hpp"

namespace {

using rigger::bench::percentile;
using rigger::bench::summarize;
using rigger::testing::Cell;
using rigger::testing::ChildProcess;

constexpr const char* kControllerHost = "controller";
constexpr const char* kExecutorsHost = "executors";

struct Options {
  int trials = 200, warmup = 10, period_ms = 10, seconds = 3, rate_hz = 1000, size = 64, rounds = 3;
};

/// Every argument is one of the flags followed by an integer (at least 1; --warmup at least 0); else why
/// not, for the usage line.
std::string parse(int argc, char** argv, Options& o) {
  const std::map<std::string, int*> flags = {
      {"--trials", &o.trials}, {"--warmup", &o.warmup}, {"--period-ms", &o.period_ms}, {"--seconds", &o.seconds},
      {"--rate", &o.rate_hz},  {"--size", &o.size},     {"--rounds", &o.rounds}};
  for (int i = 1; i < argc; i += 2) {
    const auto it = flags.find(argv[i]);
    if (it == flags.end()) return std::string("unknown argument '") + argv[i] + "'";
    if (i + 1 >= argc) return std::string(argv[i]) + " needs a value";
    std::size_t used = 0;
    int value = 0;
    try {
      value = std::stoi(argv[i + 1], &used);
    } catch (const std::exception&) {
      used = 0;
    }
    const int least = it->first == "--warmup" ? 0 : 1;
    if (used == 0 || argv[i + 1][used] != '\0' || value < least)
      return std::string(argv[i]) + " '" + argv[i + 1] + "': expected an integer of at least " + std::to_string(least);
    *it->second = value;
  }
  return "";
}

std::string slurp(const std::string& path) {
  std::ifstream in(path);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

std::string load_average() {
  std::string one, five, fifteen;
  std::ifstream("/proc/loadavg") >> one >> five >> fifteen;
  return one + " " + five + " " + fifteen;
}

/// The lab's configuration with the secured file's <Security> section: what docs/security.md tells a
/// multi-host site to write by hand. Written to `path`; @throws std::runtime_error when a file lacks
/// the sections.
std::string write_secure_lab_config(const std::string& path) {
  const std::string lab = slurp(RIGGER_SOURCE_DIR "/deploy/cyclonedds-lab.xml");
  const std::string secure = slurp(RIGGER_SOURCE_DIR "/deploy/cyclonedds-secure.xml");
  // After the root element's start: the files' header comments name the sections too.
  const auto from = secure.find("<Security>", secure.find("<CycloneDDS"));
  const auto to = secure.find("</Security>", from);
  const auto domain_end = lab.find("</Domain>", lab.find("<CycloneDDS"));
  if (from == std::string::npos || to == std::string::npos || domain_end == std::string::npos)
    throw std::runtime_error(
        "deploy/cyclonedds-secure.xml has no <Security> section, or deploy/cyclonedds-lab.xml "
        "no </Domain>: cannot make the secured lab configuration");
  const std::string section = "  " + secure.substr(from, to + 11 - from) + "\n  ";
  std::ofstream(path) << lab.substr(0, domain_end) << section << lab.substr(domain_end);
  return "file://" + path;
}

/// One of the four setups: where the processes run and how they join DDS.
struct Setup {
  std::string key;    ///< the log subfolder
  std::string label;  ///< the table's row
  bool lab = false;
  bool secure = false;
  std::string dds_uri;
};

struct Samples {
  std::vector<double> echo_us, reaction_us, to_controller_us, in_controller_us, to_executor_us;
  double trials_per_s = 0;
  int rounds = 0;
  std::size_t stray_stopped = 0;  ///< skills the executor stopped on its own (e.g. CONTROLLER_LOST)
};

/// The identity each process joins as when secured (the access table's: common/protocol/src/access.cpp).
std::string identity_of(const std::string& process) {
  static const std::map<std::string, std::string> identities = {
      {"echo", "echo"}, {"tc", "task_controller"}, {"skills", "perception-skills"}, {"monitors", "monitor_host"}};
  return identities.at(process);
}

class Runner {
 public:
  Runner(const Options& o, const rigger::bench::RunPki* pki, rigger::testing::Lab* lab) : o_(o), pki_(pki), lab_(lab) {}

  /// Measures `setup` once (echo, then the reaction) and adds to `out`. False when a measurement failed
  /// (why is on stderr).
  bool measure(const Setup& setup, int round, Samples& out) {
    // This process's participants live on the executors' host in the lab, on the machine's own network
    // otherwise; the Cells made below read CYCLONEDDS_URI (and the identity) when they are made.
    if (setup.lab)
      lab_->enter(kExecutorsHost);
    else if (lab_)
      lab_->leave();
    setenv("CYCLONEDDS_URI", setup.dds_uri.c_str(), 1);
    if (setup.secure) setenv("RIGGER_SECURITY_DIR", pki_->pki().c_str(), 1);
    const std::string folder = setup.key + "-" + std::to_string(round + 1);

    join_as(setup, "bench");
    const auto start_echo = [&](Cell& cell, std::vector<std::string> args) -> ChildProcess& {
      return start(setup, cell, "echo", "echo", std::move(args));
    };
    const auto rtt = rigger::bench::measure_echo_phase({o_.rate_hz, o_.size, o_.seconds}, start_echo, folder + "/echo");
    if (rtt.empty()) {
      std::fprintf(stderr, "%s: the echo round trip failed\n", setup.label.c_str());
      return false;
    }
    out.echo_us.insert(out.echo_us.end(), rtt.begin(), rtt.end());

    join_as(setup, "riggerctl");  // submits the recipe and reads the skill topics
    rigger::bench::ReactionSetup where;
    where.cell_subfolder = folder + "/reaction";
    where.warmup_trials = o_.warmup;
    where.allow_stray_stopped = true;
    where.start = [&](Cell& cell, const std::string& name, const std::string& binary,
                      std::vector<std::string> args) -> ChildProcess& {
      return start(setup, cell, name, binary, std::move(args));
    };
    const auto r =
        rigger::bench::measure_reaction(rigger::bench::Pattern::kMonitorFailure, "normal", o_.trials, o_.period_ms, where);
    if (!r.ok) {
      std::fprintf(stderr, "%s: the reaction failed\n", setup.label.c_str());
      return false;
    }
    const auto add = [](std::vector<double>& to, const std::vector<double>& from) {
      to.insert(to.end(), from.begin(), from.end());
    };
    add(out.reaction_us, r.command_received_us);
    add(out.to_controller_us, r.to_woke_us);
    add(out.to_executor_us, r.command_to_seen_us);
    for (std::size_t i = 0; i < r.to_writing_us.size(); ++i)
      out.in_controller_us.push_back(r.to_writing_us[i] + r.writing_us[i]);
    out.stray_stopped += r.stray_stopped;
    out.trials_per_s = (out.trials_per_s * out.rounds + r.trials_per_s) / (out.rounds + 1);
    ++out.rounds;
    return true;
  }

 private:
  void join_as(const Setup& setup, const std::string& identity) const {
    if (setup.secure) setenv("RIGGER_IDENTITY", identity.c_str(), 1);
  }

  /// `name` on its host: echo and the controller on "controller", the executors on "executors" (in the
  /// lab, through `deploy/lab-hosts exec`); with the setup's DDS configuration and, secured, its identity.
  ChildProcess& start(const Setup& setup, Cell& cell, const std::string& name, const std::string& binary,
                      std::vector<std::string> args) const {
    std::map<std::string, std::string> env = {{"CYCLONEDDS_URI", setup.dds_uri}};
    if (setup.secure) {
      env["RIGGER_SECURITY_DIR"] = pki_->pki();
      env["RIGGER_IDENTITY"] = identity_of(name);
    }
    if (!setup.lab) return cell.start(name, binary, std::move(args), true, env);
    const bool on_controller = name == "echo" || name == "tc";
    args.insert(args.begin(),
                {"exec", on_controller ? kControllerHost : kExecutorsHost, rigger::testing::bin_dir() + "/" + binary});
    for (const auto& [key, value] : lab_->env()) env[key] = value;
    return cell.start(name, RIGGER_SOURCE_DIR "/deploy/lab-hosts", std::move(args), true, env);
  }

  const Options& o_;
  const rigger::bench::RunPki* pki_;
  rigger::testing::Lab* lab_;
};

/// Saves each setup's figures, those of the others next to loopback's with security off.
int save_figures(const Options& o, const std::vector<Setup>& setups, const std::vector<Samples>& samples) {
  rigger::performance::Report report(
      "bench_network_matrix", "Echo round trip (" + std::to_string(o.size) + " B at " + std::to_string(o.rate_hz) +
                                  " Hz) and monitor FAILURE -> sibling SHUTDOWN reaction (" + std::to_string(o.trials) +
                                  " trials) over loopback and two lab hosts, security off and on, " +
                                  std::to_string(o.rounds) + " rounds, next to loopback with security off");
  using rigger::bench::add_quantiles;
  using rigger::bench::quantiles;
  const std::string base = setups[0].label;
  for (std::size_t i = 0; i < setups.size(); ++i) {
    const std::string& label = setups[i].label;
    const bool compared = i > 0;  // the first setup is the others' reference
    add_quantiles(report, "echo, " + label, quantiles(samples[i].echo_us), "us", compared ? "echo, " + base : "",
                  quantiles(samples[0].echo_us));
    add_quantiles(report, "reaction, " + label, quantiles(samples[i].reaction_us), "us",
                  compared ? "reaction, " + base : "", quantiles(samples[0].reaction_us));
    report.add({"reaction trials per s, " + label, samples[i].trials_per_s, "1/s", "", 0});
    report.add({"FAILURE -> controller p50, " + label, percentile(samples[i].to_controller_us, 0.5), "us", "", 0});
    report.add({"controller handling p50, " + label, percentile(samples[i].in_controller_us, 0.5), "us", "", 0});
    report.add({"SHUTDOWN -> executor p50, " + label, percentile(samples[i].to_executor_us, 0.5), "us", "", 0});
    report.add({"stray STOPPED, " + label, static_cast<double>(samples[i].stray_stopped), "trials", "", 0});
  }
  return rigger::performance::save_for_main(report);
}

}  // namespace

int main(int argc, char** argv) {
  Options o;
  if (const auto problem = parse(argc, argv, o); !problem.empty()) {
    std::fprintf(stderr,
                 "bench_network_matrix: %s\nusage: bench_network_matrix [--trials 200] [--warmup 10] [--period-ms 10] "
                 "[--seconds 3] "
                 "[--rate 1000] [--size 64] [--rounds 3]\n",
                 problem.c_str());
    return 2;
  }
  const std::string load_before = load_average();
  std::unique_ptr<rigger::bench::RunPki> pki;
  std::string secure_lab_uri;
  try {
    pki = std::make_unique<rigger::bench::RunPki>();
    secure_lab_uri = write_secure_lab_config(pki->folder() + "/cyclonedds-lab-secure.xml");
  } catch (const std::exception& e) {
    std::fprintf(stderr, "bench_network_matrix: %s\n", e.what());
    return 1;
  }
  const std::string loopback = rigger::testing::default_dds_config_uri();
  std::vector<Setup> setups = {
      {"loopback-plain", "loopback, security off", false, false, loopback},
      {"loopback-secure", "loopback, security on", false, true,
       std::string("file://") + RIGGER_SOURCE_DIR + "/deploy/cyclonedds-secure.xml"},
  };
  std::unique_ptr<rigger::testing::Lab> lab;
  if (geteuid() != 0) {
    std::printf(
        "Not root: the two-host setups need network namespaces (CAP_NET_ADMIN); measuring loopback "
        "only.\n");
  } else {
    try {
      lab = std::make_unique<rigger::testing::Lab>("n" + std::to_string(getpid() % 10000000),
                                                   std::vector<std::string>{kControllerHost, kExecutorsHost});
    } catch (const std::exception& e) {
      std::fprintf(stderr, "bench_network_matrix: could not make the lab of two hosts: %s\n", e.what());
      return 1;
    }
    setups.push_back({"hosts-plain", "two hosts, security off", true, false,
                      std::string("file://") + RIGGER_SOURCE_DIR + "/deploy/cyclonedds-lab.xml"});
    setups.push_back({"hosts-secure", "two hosts, security on", true, true, secure_lab_uri});
  }

  Runner runner(o, pki.get(), lab.get());
  std::vector<Samples> samples(setups.size());
  for (int round = 0; round < o.rounds; ++round) {
    for (std::size_t i = 0; i < setups.size(); ++i) {
      std::fprintf(stderr, "round %d of %d: %s\n", round + 1, o.rounds, setups[i].label.c_str());
      try {
        if (!runner.measure(setups[i], round, samples[i])) return 1;
      } catch (const std::exception& e) {  // a participant or a process that could not be made
        std::fprintf(stderr, "bench_network_matrix: %s: %s\n", setups[i].label.c_str(), e.what());
        return 1;
      }
    }
  }
  if (lab) {
    if (const auto& problems = lab->tear_down(); !problems.empty())
      std::fprintf(stderr, "bench_network_matrix: tearing the lab down: %s\n", problems.c_str());
  }
  const std::string load_after = load_average();

  std::printf("Network matrix (loopback and lab hosts, security off and on), %d round(s); load average %s before, %s after\n", o.rounds,
              load_before.c_str(), load_after.c_str());
  std::printf("echo: round trip through the echo service, %d B at %d Hz for %d s per round\n", o.size, o.rate_hz,
              o.seconds);
  std::printf(
      "reaction: monitor FAILURE written -> sibling SHUTDOWN received, Repeat(ForceSuccess(Parallel(1,1)"
      "[skill, monitor])), %d trials per round, monitor fails %d ms after its START\n",
      o.trials, o.period_ms);
  std::printf("%-26s %8s %8s %8s %7s | %8s %8s %8s %6s %7s\n", "(us)", "echo p50", "p90", "p99", "n", "react p50",
              "p90", "p99", "n", "trials/s");
  for (std::size_t i = 0; i < setups.size(); ++i) {
    const auto e = summarize(samples[i].echo_us), r = summarize(samples[i].reaction_us);
    std::printf("%-26s %8.1f %8.1f %8.1f %7zu | %8.1f %8.1f %8.1f %6zu %7.1f\n", setups[i].label.c_str(), e.p50, e.p90,
                e.p99, e.count, r.p50, r.p90, r.p99, r.count, samples[i].trials_per_s);
  }
  std::printf("Ratios against loopback, security off (this run):\n");
  std::printf("%-26s %8s %8s %8s %7s | %8s %8s %8s\n", "", "echo p50", "p90", "p99", "", "react p50", "p90", "p99");
  const auto e0 = summarize(samples[0].echo_us), r0 = summarize(samples[0].reaction_us);
  for (std::size_t i = 1; i < setups.size(); ++i) {
    const auto e = summarize(samples[i].echo_us), r = summarize(samples[i].reaction_us);
    std::printf("%-26s %8.2f %8.2f %8.2f %7s | %8.2f %8.2f %8.2f\n", setups[i].label.c_str(), e.p50 / e0.p50,
                e.p90 / e0.p90, e.p99 / e0.p99, "", r.p50 / r0.p50, r.p90 / r0.p90, r.p99 / r0.p99);
  }
  std::printf(
      "Where the reaction's time goes, p50 (us; the controller's stage trace and the skill executor's receipt "
      "trace):\n");
  std::printf("%-26s %14s %14s %14s %14s\n", "", "FAILURE->tc", "tc handling", "SHUTDOWN->exec", "stray STOPPED");
  for (std::size_t i = 0; i < setups.size(); ++i)
    std::printf("%-26s %14.1f %14.1f %14.1f %14zu\n", setups[i].label.c_str(),
                percentile(samples[i].to_controller_us, 0.5), percentile(samples[i].in_controller_us, 0.5),
                percentile(samples[i].to_executor_us, 0.5), samples[i].stray_stopped);
  std::printf(
      "(stray STOPPED: trials in which the skill's executor stopped the skill on its own, e.g. when the "
      "controller's liveliness lapsed; their reaction still counts)\n");
  return save_figures(o, setups, samples);
}
