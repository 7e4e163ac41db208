#include "rigger/service/service.hpp"

#include <pthread.h>
#include <signal.h>

#include <algorithm>
#include <chrono>
#include <iostream>
#include <thread>

#include "rigger/dds/liveliness.hpp"

namespace rigger::service {
namespace {

// Signals are taken by one dedicated thread with sigwait(): the handler-free way to turn SIGINT and
// SIGTERM into EventLoop::stop(), which is not async-signal-safe. The mask is set before any other
// thread (Cyclone's included) exists, so every thread inherits it.
class SignalThread {
 public:
  SignalThread() {
    sigemptyset(&set_);
    sigaddset(&set_, SIGINT);
    sigaddset(&set_, SIGTERM);
    sigaddset(&set_, SIGHUP);
    sigaddset(&set_, SIGUSR1);
    pthread_sigmask(SIG_BLOCK, &set_, nullptr);
  }
  void start(dds::EventLoop& loop, const Logger& log) {
    thread_ = std::thread([this, &loop, log] {
      int sig = 0;
      sigwait(&set_, &sig);
      if (sig != SIGUSR1) {
        log->info("signal received signal={} action=stop", strsignal(sig));
        loop.stop();
      }
    });
  }
  ~SignalThread() {
    if (thread_.joinable()) {
      pthread_kill(thread_.native_handle(), SIGUSR1);  // wakes sigwait when no signal came
      thread_.join();
    }
  }

 private:
  sigset_t set_;
  std::thread thread_;
};

}  // namespace

int run_service(int argc, char** argv, const ServiceSpec& spec) {
  ServiceOptions options;
  CLI::App app{spec.description, spec.kind};
  app.add_option("--id", options.id, "Service id, unique on the domain (default: the service kind)");
  app.add_option("--domain", options.domain, "DDS domain id (default: $RIGGER_DOMAIN or 0)")->check(CLI::Range(0, 232));
  app.add_option("--config", options.config_path, "Configuration file (JSON)");
  app.add_option("--log-level", options.log_level, "trace, debug, info, warn, error, critical or off");
  if (spec.add_options) spec.add_options(app);
  try {
    options.domain = dds::domain_from_environment(0);
    dds::liveliness_lease();  // a bad $RIGGER_LIVELINESS_LEASE_MS is a usage error, said here
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e) == 0 ? kExitOk : kExitUsage;
  } catch (const std::exception& e) {
    std::cerr << spec.kind << ": " << e.what() << "\n";
    return kExitUsage;
  }
  if (options.id.empty()) options.id = spec.kind;

  Logger log;
  try {
    log = make_logger(options.id, options.log_level);
  } catch (const std::exception& e) {
    std::cerr << spec.kind << ": " << e.what() << "\n";
    return kExitUsage;
  }

  SignalThread signals;  // before the participant, so Cyclone's threads inherit the blocked mask
  try {
    Config config = options.config_path.empty() ? Config::empty() : Config::load(options.config_path);
    dds::Participant participant(options.domain);
    dds::EventLoop loop(participant);
    ServiceAnnouncer announcer(participant, options.id, spec.kind);
    announcer.announce(ServiceStatus::kStarting);
    signals.start(loop, log);
    loop.on_status(announcer.writer_handle(), DDS_LIVELINESS_LOST_STATUS, [&] {
      log->warn(
          "liveliness lost: no assertion within the lease (the work loop stalled longer than {} ms, or "
          "the machine starved the asserting thread); announcing again",
          dds::kLoopStallLimit.count());
      announcer.reannounce();
    });

    // Liveliness is asserted from a thread of its own every third of the shortest lease offered (two
    // assertions' margin): while the node is built, and then as long as the loop ticked within
    // dds::kLoopStallLimit. A killed process is seen within the lease, a hung loop within the stall limit
    // plus the lease, and a loop that stalls for less (a slow write, a starved machine) costs nobody a
    // lease.
    ServiceContext ctx{options, log, participant, loop, announcer, config};
    dds::LivelinessAsserter liveliness(participant, ctx.liveliness_lease / 3);
    std::unique_ptr<Node> node = spec.make_node(ctx);
    liveliness.set_period(ctx.liveliness_lease / 3);  // the node may have offered a shorter lease
    // The loop's own periodic work is one timer, four times per stall limit, so that an idle service
    // wakes for nothing else of its own: it shows the loop's progress, and every kServiceRefreshPeriod it
    // re-announces: a reader starved of CPU may expire a lease before it processed the liveliness
    // messages queued for it, and the instance then stays NOT_ALIVE until a new sample; one small sample
    // a second heals such a false loss.
    const auto tick = std::min<std::chrono::milliseconds>(dds::kLoopStallLimit / 4, kServiceRefreshPeriod);
    const auto ticks_per_refresh = std::max<std::chrono::milliseconds::rep>(1, kServiceRefreshPeriod / tick);
    std::chrono::milliseconds::rep ticks = 0;
    liveliness.loop_alive();
    loop.every(tick, [&liveliness, &announcer, &ticks, ticks_per_refresh] {
      liveliness.loop_alive();
      if (++ticks % ticks_per_refresh == 0) announcer.reannounce();
    });
    announcer.announce(ServiceStatus::kReady);
    log->info("ready service={} kind={} domain={} pid={}", options.id, spec.kind, options.domain, getpid());
    loop.run();
    log->info("stopping service={}", options.id);
    announcer.announce(ServiceStatus::kStopping);
    node.reset();  // the node brings its devices to a safe state here
    log->info("stopped service={}", options.id);
    return kExitOk;
  } catch (const ConfigError& e) {
    log->critical("bad configuration: {}", e.what());
    return kExitUsage;
  } catch (const std::exception& e) {
    log->critical("fatal: {}", e.what());
    return kExitFailure;
  }
}

}  // namespace rigger::service
