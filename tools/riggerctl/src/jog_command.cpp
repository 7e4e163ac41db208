// `riggerctl jog`: the operator's joystick reference for admittance_control. Keyboard (terminal raw
// mode), a Linux joystick device, or a non-interactive script → sensing::TwistCommand on
// rigger/operator/joystick at a fixed rate, stamped, numbered and with a timeout. Whatever ends the
// command (q, Ctrl-C, SIGTERM, end of script, a lost device), its last command is the zero twist.
#include <fcntl.h>
#include <linux/joystick.h>
#include <poll.h>
#include <pthread.h>
#include <signal.h>
#include <termios.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <functional>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include "commands.hpp"
#include "jog_input.hpp"
#include "rigger/base/time.hpp"
#include "rigger/dds/conversions.hpp"
#include "rigger/dds/event_loop.hpp"
#include "rigger/dds/pubsub.hpp"
#include "rigger/protocol/operator.hpp"

namespace rigger::ctl {
namespace {

constexpr const char* kDefaultDevice = "/dev/input/js0";
constexpr double kMaxLinearMps = 0.25;  // admittance_control's default robot velocity limit
constexpr double kMaxAngularRadps = 0.5;

struct JogOptions {
  double speed_mps = 0.05;
  double rate_hz = 50;
  double timeout_s = 0.2;
  double hold_s = 0.6;
  double wait_s = 5;
  double deadband = 0.1;
  std::string device;
  bool keyboard = false;
  std::string script;
  std::string axes = "-1,-0,-4";
  std::string frame = "base";
  std::string source;
};

using Clock = std::chrono::steady_clock;

/// Turns SIGINT, SIGTERM and SIGHUP into a call on the event loop (a sigwait thread, as run_service
/// does). Construct before the participant so that Cyclone's threads inherit the blocked mask.
class SignalWatcher {
 public:
  SignalWatcher() {
    sigemptyset(&set_);
    for (int s : {SIGINT, SIGTERM, SIGHUP, SIGUSR1}) sigaddset(&set_, s);
    pthread_sigmask(SIG_BLOCK, &set_, nullptr);
  }
  SignalWatcher(const SignalWatcher&) = delete;
  SignalWatcher& operator=(const SignalWatcher&) = delete;
  void start(dds::EventLoop& loop, std::function<void(int)> on_signal) {
    thread_ = std::thread([this, &loop, on_signal] {
      int sig = 0;
      sigwait(&set_, &sig);
      if (sig != SIGUSR1) loop.post([on_signal, sig] { on_signal(sig); });
    });
  }
  /// Ends the watching thread (before the loop it posts to goes away). Signals stay blocked.
  void stop() {
    if (thread_.joinable()) {
      pthread_kill(thread_.native_handle(), SIGUSR1);
      thread_.join();
    }
  }
  ~SignalWatcher() { stop(); }

 private:
  sigset_t set_;
  std::thread thread_;
};

/// Reads a file descriptor on a thread of its own (poll on it and on a wake-up pipe: no busy loop) and
/// hands the bytes to the event loop. The owner must outlive the loop's handling of what it posted.
class FdReader {
 public:
  FdReader(dds::EventLoop& loop, int fd, std::function<void(std::string)> on_bytes,
           std::function<void(std::string)> on_end) {
    if (pipe(wake_) != 0) throw std::runtime_error(std::string("pipe: ") + std::strerror(errno));
    thread_ = std::thread([this, &loop, fd, on_bytes, on_end] {
      for (;;) {
        pollfd fds[2] = {{fd, POLLIN, 0}, {wake_[0], POLLIN, 0}};
        if (poll(fds, 2, -1) < 0) {
          if (errno == EINTR) continue;
          loop.post([on_end, e = std::string(std::strerror(errno))] { on_end("poll: " + e); });
          return;
        }
        if (fds[1].revents) return;
        char buffer[256];
        const ssize_t n = read(fd, buffer, sizeof buffer);
        if (n < 0 && (errno == EINTR || errno == EAGAIN)) continue;
        if (n <= 0) {
          const std::string why = n == 0 ? "end of input" : std::strerror(errno);
          loop.post([on_end, why] { on_end(why); });
          return;
        }
        loop.post([on_bytes, bytes = std::string(buffer, static_cast<std::size_t>(n))] { on_bytes(bytes); });
      }
    });
  }
  FdReader(const FdReader&) = delete;
  FdReader& operator=(const FdReader&) = delete;
  ~FdReader() {
    const char c = 0;
    if (write(wake_[1], &c, 1) < 0) {
      // The pipe cannot be full or closed here; nothing else to do.
    }
    thread_.join();
    close(wake_[0]);
    close(wake_[1]);
  }

 private:
  int wake_[2] = {-1, -1};
  std::thread thread_;
};

/// Puts the terminal in raw mode (no line buffering, no echo, no signals from keys: Ctrl-C arrives as
/// a key and quits through the same path as q) and restores it on destruction.
class RawTerminal {
 public:
  explicit RawTerminal(int fd) : fd_(fd) {
    if (tcgetattr(fd_, &saved_) != 0) throw std::runtime_error(std::string("tcgetattr: ") + std::strerror(errno));
    termios raw = saved_;
    raw.c_lflag &= ~static_cast<tcflag_t>(ICANON | ECHO | ISIG | IEXTEN);
    raw.c_iflag &= ~static_cast<tcflag_t>(IXON | ICRNL);
    raw.c_cc[VMIN] = 1;
    raw.c_cc[VTIME] = 0;
    if (tcsetattr(fd_, TCSANOW, &raw) != 0) throw std::runtime_error(std::string("tcsetattr: ") + std::strerror(errno));
  }
  RawTerminal(const RawTerminal&) = delete;
  RawTerminal& operator=(const RawTerminal&) = delete;
  ~RawTerminal() { tcsetattr(fd_, TCSANOW, &saved_); }

 private:
  int fd_;
  termios saved_{};
};

/// Publishes TwistCommands: stamped now, numbered from 1, with the consumer's timeout.
class TwistPublisher {
 public:
  TwistPublisher(dds::Participant& participant, const JogOptions& opt)
      : writer_(participant, protocol::operator_ui::kJoystick),
        frame_(opt.frame),
        source_(opt.source),
        timeout_s_(opt.timeout_s) {}

  void publish(const jog::Twist& twist) {
    rigger_sensing_TwistCommand c{};
    c.header.stamp = dds::wire_now();
    c.header.frame_id = dds::wire_string(frame_);
    c.seq = ++seq_;
    dds::Vector6d v;
    for (int i = 0; i < 6; ++i) v[i] = twist[static_cast<std::size_t>(i)];
    c.twist = dds::to_wire_twist(v);
    c.timeout_s = timeout_s_;
    c.source = dds::wire_string(source_);
    const auto rc = writer_.write(c);
    if (rc != DDS_RETCODE_OK) std::fprintf(stderr, "riggerctl: twist write failed: %s\n", dds_strretcode(rc));
    last_ = twist;
  }
  /// Waits until the matched readers acknowledged every command (the final zero above all).
  void flush(std::chrono::nanoseconds timeout) { dds_wait_for_acks(writer_.handle(), timeout.count()); }
  const dds::Writer<rigger_sensing_TwistCommand>& writer() const { return writer_; }
  std::uint64_t seq() const { return seq_; }
  const jog::Twist& last() const { return last_; }

 private:
  dds::Writer<rigger_sensing_TwistCommand> writer_;
  std::string frame_;
  std::string source_;
  double timeout_s_;
  std::uint64_t seq_ = 0;
  jog::Twist last_{};
};

enum class Input { kScript, kKeyboard, kDevice };

int run(const CommonOptions& common, JogOptions opt) {
  // Everything that can be wrong with the command line is checked before anything is published.
  std::vector<jog::ScriptStep> script;
  jog::AxisMap axis_map;
  Input input = Input::kKeyboard;
  try {
    if (!opt.script.empty()) {
      input = Input::kScript;
      script = jog::parse_script(opt.script, kMaxLinearMps, kMaxAngularRadps);
    } else if (!opt.device.empty() || (!opt.keyboard && std::filesystem::exists(kDefaultDevice))) {
      input = Input::kDevice;
      if (opt.device.empty()) opt.device = kDefaultDevice;
      axis_map = jog::parse_axis_map(opt.axes);
    } else if (!isatty(STDIN_FILENO)) {
      throw std::invalid_argument("stdin is not a terminal: use --script or --device for non-interactive jogging");
    }
  } catch (const std::invalid_argument& e) {
    std::fprintf(stderr, "riggerctl jog: %s\n", e.what());
    return 2;
  }
  int device_fd = -1;
  if (input == Input::kDevice) {
    device_fd = open(opt.device.c_str(), O_RDONLY | O_CLOEXEC);
    if (device_fd < 0) {
      std::fprintf(stderr, "riggerctl jog: cannot open joystick %s: %s\n", opt.device.c_str(), std::strerror(errno));
      return 1;
    }
  }
  struct FdCloser {
    int fd;
    ~FdCloser() {
      if (fd >= 0) close(fd);
    }
  } device_closer{device_fd};
  if (opt.source.empty()) {
    char host[256] = {};
    gethostname(host, sizeof host - 1);
    opt.source = std::string("riggerctl-jog@") + host;
  }

  SignalWatcher signals;
  dds::Participant participant(common.domain);
  dds::EventLoop loop(participant);
  TwistPublisher publisher(participant, opt);

  bool done = false;
  int exit_code = 0;
  std::string end_reason;
  auto finish = [&](const std::string& reason, int code) {
    if (done) return;
    done = true;
    end_reason = reason;
    exit_code = code;
  };
  signals.start(loop, [&](int sig) { finish(std::string("signal ") + strsignal(sig), 0); });

  const bool have_reader = publisher.writer().wait_for_readers(
      1, from_seconds(input == Input::kScript ? opt.wait_s : std::min(opt.wait_s, 1.0)));
  if (!have_reader && input == Input::kScript) {
    std::fprintf(stderr, "riggerctl jog: no reader of %s on %s after %.1f s (is admittance_control running?)\n",
                 protocol::operator_ui::kJoystick.name, dds::describe_domain(common.domain).c_str(), opt.wait_s);
    signals.stop();
    return 1;
  }
  if (!have_reader)
    std::fprintf(stderr, "riggerctl jog: no reader of %s yet (is admittance_control running?); publishing anyway\n",
                 protocol::operator_ui::kJoystick.name);

  jog::Twist held{};               // keyboard: the twist of the last key; device: from the sticks
  Clock::time_point held_until{};  // keyboard: a key holds its twist this long (terminal auto-repeat renews it)
  std::vector<double> axes;        // device: normalised axis values
  std::string key_bytes, device_bytes;
  std::string shown;
  const Clock::time_point start = Clock::now();

  auto show = [&](const jog::Twist& t) {
    if (input == Input::kScript) return;
    const std::string text = jog::describe(t);
    if (text == shown) return;
    shown = text;
    std::printf("\rjog: %-40s", text.c_str());
    std::fflush(stdout);
  };
  auto current = [&]() -> std::optional<jog::Twist> {
    switch (input) {
      case Input::kScript:
        return jog::script_twist_at(script, std::chrono::duration<double>(Clock::now() - start).count());
      case Input::kKeyboard:
        return Clock::now() < held_until ? held : jog::Twist{};
      case Input::kDevice:
        return held;
    }
    return jog::Twist{};
  };
  auto tick = [&] {
    if (done) return;
    const auto twist = current();
    if (!twist) {
      finish("end of script", 0);
      return;
    }
    publisher.publish(*twist);
    show(*twist);
  };

  std::unique_ptr<RawTerminal> terminal;
  std::unique_ptr<FdReader> reader;
  if (input == Input::kKeyboard) {
    terminal = std::make_unique<RawTerminal>(STDIN_FILENO);
    std::printf("jog on domain %u at %.0f Hz, %.3f m/s: arrows/WASD x,y  R/F z  space stop  q quit\n", common.domain,
                opt.rate_hz, opt.speed_mps);
    reader = std::make_unique<FdReader>(
        loop, STDIN_FILENO,
        [&](const std::string& bytes) {
          key_bytes += bytes;
          for (const auto key : jog::decode_keys(key_bytes)) {
            if (key == jog::Key::kQuit) finish("quit", 0);
            if (key == jog::Key::kOther) continue;
            held = jog::key_twist(key, opt.speed_mps);
            held_until = key == jog::Key::kStop ? Clock::time_point{} : Clock::now() + from_seconds(opt.hold_s);
          }
          tick();  // react at once, not at the next period
        },
        [&](const std::string& why) { finish("keyboard: " + why, 0); });
  } else if (input == Input::kDevice) {
    std::printf("jog on domain %u at %.0f Hz, %.3f m/s from %s (axes %s); Ctrl-C quits\n", common.domain, opt.rate_hz,
                opt.speed_mps, opt.device.c_str(), opt.axes.c_str());
    reader = std::make_unique<FdReader>(
        loop, device_fd,
        [&](const std::string& bytes) {
          device_bytes += bytes;
          while (device_bytes.size() >= sizeof(js_event)) {
            js_event e{};
            std::memcpy(&e, device_bytes.data(), sizeof e);
            device_bytes.erase(0, sizeof e);
            if ((e.type & ~JS_EVENT_INIT) != JS_EVENT_AXIS) continue;
            if (axes.size() <= e.number) axes.resize(e.number + 1U, 0.0);
            axes[e.number] = jog::normalise_axis(e.value, opt.deadband);
          }
          held = jog::stick_twist(axes, axis_map, opt.speed_mps);
        },
        [&](const std::string& why) { finish("joystick " + opt.device + ": " + why, 1); });
  }

  tick();
  loop.every(from_seconds(1.0 / opt.rate_hz), tick);
  while (!done && !loop.stop_requested()) loop.run_until([&] { return done; }, std::chrono::hours(24));

  // The last word is always zero, and it is delivered before the process exits.
  publisher.publish(jog::Twist{});
  publisher.flush(std::chrono::seconds(2));
  reader.reset();
  terminal.reset();
  signals.stop();
  if (input != Input::kScript) std::printf("\n");
  std::printf("jog ended (%s): %llu commands published, the last one zero\n", end_reason.c_str(),
              static_cast<unsigned long long>(publisher.seq()));
  if (exit_code != 0) std::fprintf(stderr, "riggerctl jog: %s\n", end_reason.c_str());
  return exit_code;
}

}  // namespace

void add_jog_command(CLI::App& app, const CommonOptions& common, int& exit_code) {
  auto opt = std::make_shared<JogOptions>();
  auto* cmd =
      app.add_subcommand("jog", "Jog the robot: keyboard, joystick device or script -> rigger/operator/joystick");
  cmd->add_option("--speed", opt->speed_mps, "Linear speed of a key or a full stick [m/s] (default 0.05)")
      ->check(CLI::Range(0.001, kMaxLinearMps));
  cmd->add_option("--rate", opt->rate_hz, "Publication rate [Hz] (default 50)")->check(CLI::Range(1.0, 1000.0));
  cmd->add_option("--timeout", opt->timeout_s,
                  "The commands' timeout_s: a consumer that sees nothing newer commands zero (default 0.2)")
      ->check(CLI::Range(0.01, 10.0));
  cmd->add_option("--hold", opt->hold_s,
                  "Keyboard: how long a key press holds its twist; the terminal's key repeat renews it (default 0.6)")
      ->check(CLI::Range(0.05, 5.0));
  cmd->add_option("--device", opt->device, "Linux joystick device (default: /dev/input/js0 when present)");
  cmd->add_flag("--keyboard", opt->keyboard, "Use the keyboard even when a joystick is present");
  cmd->add_option("--axes", opt->axes, "Joystick axes for x,y,z with signs (default -1,-0,-4)");
  cmd->add_option("--deadband", opt->deadband, "Joystick deadband, fraction of full scale (default 0.1)")
      ->check(CLI::Range(0.0, 0.9));
  cmd->add_option("--script", opt->script,
                  "Non-interactive: steps 'x+0.05:2s,y-0.02z+0.01:500ms,stop:1s' (m/s, rad/s for rx/ry/rz), then zero");
  cmd->add_option("--wait", opt->wait_s,
                  "Seconds to wait for a reader of the topic; --script fails without one (default 5)")
      ->check(CLI::Range(0.0, 600.0));
  cmd->add_option("--frame", opt->frame, "header.frame_id (default base)");
  cmd->add_option("--source", opt->source, "The commands' source (default riggerctl-jog@host)");
  cmd->callback([&common, &exit_code, opt] { exit_code = run(common, *opt); });
}

}  // namespace rigger::ctl
