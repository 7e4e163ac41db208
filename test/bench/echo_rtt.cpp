#include "echo_rtt.hpp"

#include <signal.h>

#include <cstdint>
#include <cstdio>
#include <string>

#include "bench_util.hpp"

#include "rigger/dds/conversions.hpp"
#include "rigger/dds/pubsub.hpp"
#include "rigger/protocol/system.hpp"

namespace rigger::bench {
namespace {

using namespace std::chrono_literals;
using Clock = std::chrono::steady_clock;

// Same QoS as the echo service and as ddsperf's ping/pong: reliable, keep-last 1.
rigger::dds::Qos echo_qos() {
  rigger::dds::Qos q;
  q.reliable().keep_last(1).volatile_durability();
  return q;
}

}  // namespace

std::vector<double> measure_echo_rtt(rigger::testing::Cell& cell, const EchoRun& run) {
  auto& participant = cell.participant();
  auto& loop = cell.loop();
  rigger::dds::Writer<rigger_system_EchoSample> requests(participant, rigger::protocol::system::kEchoRequest,
                                                         echo_qos());
  rigger::dds::Reader<rigger_system_EchoSample> replies(participant, rigger::protocol::system::kEchoReply, echo_qos());
  if (!requests.wait_for_readers(1, 10s) || !replies.wait_for_writers(1, 10s)) return {};

  const std::string client = "bench";
  std::vector<std::uint8_t> payload(static_cast<size_t>(run.size), 0xAB);
  std::vector<double> rtt_us;
  rtt_us.reserve(static_cast<size_t>(run.rate_hz * run.seconds));
  std::uint64_t seq = 0;
  const auto warmup_end = Clock::now() + 1s;  // excluded, as the first ddsperf second is
  const auto end = warmup_end + std::chrono::seconds(run.seconds);
  loop.on_data(replies, [&] {
    const auto now = Clock::now();
    replies.take([&](const rigger_system_EchoSample& s, const dds_sample_info_t&) {
      if (now < warmup_end) return;
      const auto sent = Clock::time_point(std::chrono::nanoseconds(s.sent_ns));
      rtt_us.push_back(std::chrono::duration<double, std::micro>(now - sent).count());
    });
  });
  const auto timer = loop.every(std::chrono::nanoseconds(1'000'000'000 / run.rate_hz), [&] {
    rigger_system_EchoSample req{};
    req.client_id = rigger::dds::wire_string(client);
    req.seq = ++seq;
    req.sent_ns = std::chrono::duration_cast<std::chrono::nanoseconds>(Clock::now().time_since_epoch()).count();
    rigger::dds::wire_sequence(req.payload, payload);
    requests.write(req);
  });
  loop.run_until([&] { return Clock::now() >= end; }, end - Clock::now() + 1s);
  loop.cancel(timer);
  return rtt_us;
}

RttFigures summarize(const std::vector<double>& us) {
  return {percentile(us, 0.50), percentile(us, 0.90), percentile(us, 0.99), us.size()};
}

std::vector<double> measure_echo_phase(const EchoRun& run, const StartEcho& start_echo,
                                       const std::string& cell_subfolder) {
  rigger::testing::Cell cell(cell_subfolder);
  auto& echo = start_echo(cell, {"--id", "echo", "--log-level", "warn"});
  if (!cell.wait_ready({"echo"}, 20s)) {
    std::fprintf(stderr, "echo did not become ready\n%s\n", echo.log().c_str());
    return {};
  }
  auto rtt = measure_echo_rtt(cell, run);
  echo.signal(SIGINT);
  echo.wait(5s);
  if (rtt.empty()) std::fprintf(stderr, "echo's endpoints did not match\n%s\n", echo.log().c_str());
  return rtt;
}

}  // namespace rigger::bench
