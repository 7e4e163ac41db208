// libFuzzer target: whatever a PLC (or something pretending to be one) answers, the gateway's
// decoding must not crash, must accept only what re-encodes to the very same registers, and
// must never produce a command block that is invalid or exceeds the configured speeds.
//
// Input: 28 bytes status block, 40 bytes limits block (big-endian registers, as on the wire),
// then any number of further 28-byte status blocks fed through the gateway logic.
#include <cstddef>
#include <cstdint>
#include <cstdlib>

#include "gateway_logic.hpp"
#include "rigger/crane_protocol/register_map.hpp"
#include "rigger/crane_protocol/testing.hpp"

namespace {

using ::rigger::crane::testing::reference_limits;

using namespace rigger;
using namespace std::chrono_literals;

template <std::size_t N>
bool take(const std::uint8_t*& data, std::size_t& size, std::array<std::uint16_t, N>& out) {
  if (size < 2 * N) {
    return false;
  }
  for (std::size_t i = 0; i < N; ++i) {
    out[i] = static_cast<std::uint16_t>((data[2 * i] << 8U) | data[2 * i + 1]);
  }
  data += 2 * N;
  size -= 2 * N;
  return true;
}

void check(bool condition) {
  if (!condition) {
    std::abort();
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  crane::StatusRegisters status{};
  crane::LimitRegisters limits{};
  if (!take(data, size, status) || !take(data, size, limits)) {
    return 0;
  }
  crane::Plausibility plausibility;
  plausibility.limits = reference_limits();

  const auto decoded_status = crane::decode_status(status, plausibility);
  if (decoded_status) {
    const auto again = crane::encode_status(*decoded_status.value);
    check(!again.saturated);
    check(again.registers == status);
  } else {
    check(!decoded_status.error.field.empty() && !decoded_status.error.reason.empty());
  }
  const auto decoded_limits = crane::decode_limits(limits);
  if (decoded_limits) {
    const auto again = crane::encode_limits(*decoded_limits.value);
    check(!again.saturated);
    check(again.registers == limits);
  }

  crane_gateway::GatewayLogicConfig config;
  config.plausibility = plausibility;
  crane_gateway::GatewayLogic logic(config);
  const crane_gateway::WallTime wall0{std::chrono::seconds(1'700'000'000)};
  const crane_gateway::SteadyTime steady0{std::chrono::seconds(1000)};
  if (logic.on_connected(limits, wall0, steady0)) {
    check(!logic.state().link_up);
    return 0;
  }
  logic.set_control({true, true});
  crane_gateway::VelocityCommand command;
  command.velocity_mps = {3.0, -3.0, 3.0};  // beyond every limit: the gateway must clamp
  command.stamp = wall0 + 1ms;
  command.seq = 1;
  logic.submit(command, wall0 + 1ms);
  int cycle = 1;
  do {
    const auto t = std::chrono::milliseconds(cycle++);
    logic.on_status(status, steady0 + t);
    const auto written = crane::decode_command(logic.next_command(wall0 + t));
    check(written.value.has_value());
    const auto& v = written.value->velocity_mps;
    const auto& max = plausibility.limits.max_speed_mps;
    check((v.cwiseAbs() - max).maxCoeff() <= 0.0005);
    if (!logic.state().external_control_granted) {
      check(v.isZero());
    }
  } while (take(data, size, status));
  return 0;
}
