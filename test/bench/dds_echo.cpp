// Round-trip latency of rigger's typed DDS layer (rigger::dds Writer/Reader + EventLoop, in this
// process and in the echo service) next to Cyclone's own ddsperf ping/pong, measured in the same run on
// the same domain configuration, payload size and rate. Targets (issue 2): p50 ratio <= 1.5, p99 <= 2.
//
//   build/bench/bench_dds_echo [--rate 1000] [--size 64] [--seconds 10]
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "bench_util.hpp"
#include "rigger/dds/conversions.hpp"
#include "rigger/dds/pubsub.hpp"
#include "rigger/protocol/system.hpp"
#include "rigger/testing/cell.hpp"

namespace {

using namespace std::chrono_literals;
using Clock = std::chrono::steady_clock;

struct Options {
  int rate_hz = 1000;
  int size = 64;
  int seconds = 10;
};

Options parse(int argc, char** argv) {
  using rigger::bench::int_option;
  return {int_option(argc, argv, "--rate", 1000), int_option(argc, argv, "--size", 64),
          int_option(argc, argv, "--seconds", 10)};
}

// Same QoS as the echo service and as ddsperf's ping/pong: reliable, keep-last 1.
rigger::dds::Qos echo_qos() {
  rigger::dds::Qos q;
  q.reliable().keep_last(1).volatile_durability();
  return q;
}

}  // namespace

int main(int argc, char** argv) {
  const Options opt = parse(argc, argv);
  rigger::testing::Cell cell;
  cell.start("echo", "echo", {"--id", "echo", "--log-level", "warn"});
  if (!cell.wait_ready({"echo"}, 10s)) {
    std::fprintf(stderr, "echo did not become ready\n%s", cell.logs().c_str());
    return 1;
  }

  auto& participant = cell.participant();
  auto& loop = cell.loop();
  rigger::dds::Writer<rigger_system_EchoSample> requests(participant, rigger::protocol::system::kEchoRequest,
                                                         echo_qos());
  rigger::dds::Reader<rigger_system_EchoSample> replies(participant, rigger::protocol::system::kEchoReply, echo_qos());
  if (!requests.wait_for_readers(1, 5s)) {
    std::fprintf(stderr, "echo's request reader did not match\n");
    return 1;
  }

  const std::string client = "bench";
  std::vector<std::uint8_t> payload(static_cast<size_t>(opt.size), 0xAB);
  std::vector<double> rtt_us;
  rtt_us.reserve(static_cast<size_t>(opt.rate_hz * opt.seconds));
  std::uint64_t seq = 0;
  const auto warmup_end = Clock::now() + 1s;  // excluded, as the first ddsperf second is
  const auto end = warmup_end + std::chrono::seconds(opt.seconds);
  loop.on_data(replies, [&] {
    const auto now = Clock::now();
    replies.take([&](const rigger_system_EchoSample& s, const dds_sample_info_t&) {
      if (now < warmup_end) return;
      const auto sent = Clock::time_point(std::chrono::nanoseconds(s.sent_ns));
      rtt_us.push_back(std::chrono::duration<double, std::micro>(now - sent).count());
    });
  });
  loop.every(std::chrono::nanoseconds(1'000'000'000 / opt.rate_hz), [&] {
    rigger_system_EchoSample req{};
    req.client_id = rigger::dds::wire_string(client);
    req.seq = ++seq;
    req.sent_ns = std::chrono::duration_cast<std::chrono::nanoseconds>(Clock::now().time_since_epoch()).count();
    rigger::dds::wire_sequence(req.payload, payload);
    requests.write(req);
  });
  loop.run_until([&] { return Clock::now() >= end; }, end - Clock::now() + 1s);
  cell.stop_all();

  using rigger::bench::percentile;
  const double r50 = percentile(rtt_us, 0.50), r90 = percentile(rtt_us, 0.90), r99 = percentile(rtt_us, 0.99);
  const auto ref = rigger::bench::run_ddsperf_pingpong(cell.domain_id(), opt.rate_hz, opt.size, opt.seconds, false);
  const auto ref_ws = rigger::bench::run_ddsperf_pingpong(cell.domain_id(), opt.rate_hz, opt.size, opt.seconds, true);
  if (ref.count == 0 || ref_ws.count == 0) {
    std::fprintf(stderr, "could not parse ddsperf output:\n%s\n%s\n", ref.raw.c_str(), ref_ws.raw.c_str());
    return 1;
  }

  std::printf("DDS round trip, %d B payload at %d Hz for %d s, loopback (deploy/cyclonedds.xml), domain %u\n",
              opt.size, opt.rate_hz, opt.seconds, cell.domain_id());
  std::printf("%-42s %10s %10s %10s %8s\n", "", "p50 us", "p90 us", "p99 us", "samples");
  std::printf("%-42s %10.1f %10.1f %10.1f %8zu\n", "rigger typed layer (EventLoop, echo service)", r50, r90, r99,
              rtt_us.size());
  std::printf("%-42s %10.1f %10.1f %10.1f %8llu\n", "ddsperf ping/pong, listener (default)", ref.p50_us, ref.p90_us,
              ref.p99_us, static_cast<unsigned long long>(ref.count));
  std::printf("%-42s %10.1f %10.1f %10.1f %8llu\n", "ddsperf ping/pong, waitset", ref_ws.p50_us, ref_ws.p90_us,
              ref_ws.p99_us, static_cast<unsigned long long>(ref_ws.count));
  std::printf("ratio vs ddsperf listener: p50 %.2f (target <= 1.5)  p99 %.2f (target <= 2)\n", r50 / ref.p50_us,
              r99 / ref.p99_us);
  std::printf("ratio vs ddsperf waitset:  p50 %.2f  p99 %.2f\n", r50 / ref_ws.p50_us, r99 / ref_ws.p99_us);
  return 0;
}
