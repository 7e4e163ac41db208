#include <cstdio>
#include <string>

#include "commands.hpp"
#include "rigger/dds/event_loop.hpp"
#include "rigger/service/service_state.hpp"

namespace rigger::ctl {
namespace {

struct ServicesOptions {
  unsigned wait_ready = 0;
  std::string wait_lost;
  double timeout_s = 10;
};

void print_table(const service::ServiceDirectory& dir) {
  std::printf("%-24s %-18s %-9s %-6s %8s  %s\n", "SERVICE", "KIND", "STATE", "ALIVE", "PID", "HOST");
  for (const auto& [id, s] : dir.services())
    std::printf("%-24s %-18s %-9s %-6s %8d  %s\n", id.c_str(), s.kind.c_str(), service::to_string(s.status),
                s.alive ? "yes" : "LOST", s.pid, s.host.c_str());
}

int run(const CommonOptions& common, const ServicesOptions& opt) {
  dds::Participant participant(common.domain);
  dds::EventLoop loop(participant);
  service::ServiceDirectory dir(participant);
  const auto start = std::chrono::steady_clock::now();
  auto elapsed_ms = [&] {
    return std::chrono::duration_cast<std::chrono::milliseconds>(std::chrono::steady_clock::now() - start).count();
  };
  size_t last_ready = 0;
  loop.on_data(dir.reader(), [&] {
    if (!dir.update()) return;
    const auto ready = dir.ready_ids().size();
    if (opt.wait_ready && ready != last_ready) {
      std::printf("  %6lld ms  %zu/%u services ready\n", static_cast<long long>(elapsed_ms()), ready, opt.wait_ready);
      std::fflush(stdout);
      last_ready = ready;
    }
  });
  const auto timeout = std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::duration<double>(opt.timeout_s));

  if (!opt.wait_lost.empty()) {
    const bool seen = loop.run_until([&] { return dir.is_ready(opt.wait_lost); }, timeout);
    if (!seen) {
      std::fprintf(stderr, "riggerctl: service '%s' is not ready on %s\n", opt.wait_lost.c_str(),
                   dds::describe_domain(common.domain).c_str());
      return 1;
    }
    const auto t0 = std::chrono::steady_clock::now();
    if (!loop.run_until([&] { return !dir.is_ready(opt.wait_lost); }, timeout)) {
      std::fprintf(stderr, "riggerctl: service '%s' still alive after %.1f s\n", opt.wait_lost.c_str(), opt.timeout_s);
      return 1;
    }
    const auto ms = std::chrono::duration_cast<std::chrono::milliseconds>(std::chrono::steady_clock::now() - t0).count();
    std::printf("service %s lost, noticed %lld ms after this command started watching for it\n", opt.wait_lost.c_str(),
                static_cast<long long>(ms));
    return 0;
  }
  if (opt.wait_ready) {
    const bool ok = loop.run_until([&] { return dir.ready_ids().size() >= opt.wait_ready; }, timeout);
    print_table(dir);
    if (!ok) {
      std::fprintf(stderr, "riggerctl: only %zu of %u services ready after %.1f s\n", dir.ready_ids().size(),
                   opt.wait_ready, opt.timeout_s);
      return 1;
    }
    return 0;
  }
  // Plain listing: transient-local announcements arrive right after discovery; give it a moment.
  loop.run_until([] { return false; }, std::chrono::milliseconds(1500));
  print_table(dir);
  if (dir.services().empty())
    std::fprintf(stderr, "riggerctl: no service on %s\n", dds::describe_domain(common.domain).c_str());
  return 0;
}

}  // namespace

void add_services_command(CLI::App& app, const CommonOptions& common, int& exit_code) {
  auto opt = std::make_shared<ServicesOptions>();
  auto* cmd = app.add_subcommand("services", "List the rigger services alive on the domain");
  cmd->add_option("--wait", opt->wait_ready, "Wait until at least N services are READY");
  cmd->add_option("--lost", opt->wait_lost, "Wait until service ID, now ready, is lost; print how long it took");
  cmd->add_option("--timeout", opt->timeout_s, "Seconds to wait (default 10)");
  cmd->callback([&common, &exit_code, opt] { exit_code = run(common, *opt); });
}

}  // namespace rigger::ctl
