#include "rigger/plc/plc_emulator.hpp"

#include <algorithm>

namespace rigger::plc {

namespace reg = crane::reg;

PlcEmulator::PlcEmulator(PlcEmulatorConfig config, CraneAxesIo& axes)
    : axes_(axes),
      server_(config.server, reg::kRegisterCount, reg::kCommandBlockStart, reg::kWritableCount),
      program_(config.program) {
  const auto limits = crane::encode_limits(program_.config().limits).registers;
  server_.with_registers([&](std::uint16_t* registers, std::size_t) {
    std::copy(limits.begin(), limits.end(), registers + reg::kLimitsBlockStart);
  });
  // A first scan before anyone can connect, so that the status block never shows the all-zero
  // start-up memory (which would put the hook on the floor).
  step(std::chrono::nanoseconds::zero());
}

PlcEmulator::~PlcEmulator() {
  stop_cycle_thread();
  server_.stop();
}

void PlcEmulator::start_server() { server_.start(); }

void PlcEmulator::stop_server() { server_.stop(); }

void PlcEmulator::step(std::chrono::nanoseconds dt) {
  const CraneAxesMeasurement measured = axes_.read();
  PlcOutputs outputs;
  {
    const std::lock_guard<std::mutex> lock(mutex_);
    // One critical section for read, program and write, so that a client never sees a status
    // block that belongs to another command than the one the program acted on.
    server_.with_registers([&](std::uint16_t* registers, std::size_t) {
      std::copy_n(registers + reg::kCommandBlockStart, reg::kCommandBlockCount,
                  snapshot_.command_registers.begin());
      const auto decoded = crane::decode_command(snapshot_.command_registers);
      PlcInputs inputs;
      inputs.command = decoded.value;
      inputs.gateway_heartbeat = snapshot_.command_registers[reg::kGatewayHeartbeat];
      inputs.measured = measured;
      outputs = program_.cycle(inputs, dt);
      const auto status = crane::encode_status(outputs.status).registers;
      std::copy(status.begin(), status.end(), registers + reg::kStatusBlockStart);
      snapshot_.command = decoded.value;
    });
    snapshot_.status = outputs.status;
    snapshot_.velocity_command_mps = outputs.velocity_command_mps;
    snapshot_.program_time = program_.time();
    snapshot_.emergency_stop_pressed = program_.emergency_stop_pressed();
    ++snapshot_.cycles;
  }
  cycled_.notify_all();
  axes_.apply_velocity(outputs.velocity_command_mps);
}

void PlcEmulator::start_cycle_thread(std::chrono::nanoseconds period,
                                     std::function<void(std::chrono::nanoseconds)> before_step) {
  const std::lock_guard<std::mutex> lock(thread_mutex_);
  if (thread_.joinable()) {
    return;
  }
  thread_stop_ = false;
  thread_ =
      std::thread([this, period, hook = std::move(before_step)] { cycle_loop(period, hook); });
}

void PlcEmulator::stop_cycle_thread() {
  {
    const std::lock_guard<std::mutex> lock(thread_mutex_);
    if (!thread_.joinable()) {
      return;
    }
    thread_stop_ = true;
  }
  thread_wake_.notify_all();
  thread_.join();
}

void PlcEmulator::cycle_loop(std::chrono::nanoseconds period,
                             const std::function<void(std::chrono::nanoseconds)>& before_step) {
  using Clock = std::chrono::steady_clock;
  auto last = Clock::now();
  auto next = last;
  for (;;) {
    next += period;
    {
      std::unique_lock<std::mutex> lock(thread_mutex_);
      if (thread_wake_.wait_until(lock, next, [this] { return thread_stop_; })) {
        return;
      }
    }
    const auto now = Clock::now();
    // The measured dt, not the nominal period: a starved thread must not slow the PLC's clock
    // (and with it the heartbeat watchdog) down.
    const auto dt = std::chrono::duration_cast<std::chrono::nanoseconds>(now - last);
    last = now;
    if (before_step) {
      before_step(dt);
    }
    step(dt);
    if (now - next > 5 * period) {
      next = now;  // after a long stall, resume the rhythm instead of catching up in a burst
    }
  }
}

void PlcEmulator::set_emergency_stop(bool pressed) {
  const std::lock_guard<std::mutex> lock(mutex_);
  program_.set_emergency_stop(pressed);
}

PlcSnapshot PlcEmulator::snapshot() const {
  PlcSnapshot copy;
  {
    const std::lock_guard<std::mutex> lock(mutex_);
    copy = snapshot_;
  }
  copy.server = server_.stats();
  return copy;
}

bool PlcEmulator::wait_until(const std::function<bool(const PlcSnapshot&)>& predicate,
                             std::chrono::nanoseconds timeout) const {
  const auto deadline = std::chrono::steady_clock::now() + timeout;
  std::unique_lock<std::mutex> lock(mutex_);
  return cycled_.wait_until(lock, deadline, [&] {
    PlcSnapshot copy = snapshot_;
    copy.server = server_.stats();
    return predicate(copy);
  });
}

}  // namespace rigger::plc
