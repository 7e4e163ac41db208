#include "behaviour.hpp"

namespace rigger::scripted {

Behaviour parse_behaviour(const Config& config, const Behaviour& fallback) {
  Behaviour b = fallback;
  const std::string mode =
      config.get_enum("mode", to_string(fallback.mode), {"succeed", "fail", "run", "crash", "hang"});
  if (mode == "succeed") b.mode = Mode::kSucceed;
  else if (mode == "fail") b.mode = Mode::kFail;
  else if (mode == "run") b.mode = Mode::kRun;
  else if (mode == "crash") b.mode = Mode::kCrash;
  else b.mode = Mode::kHang;
  b.delay_s = config.get_in_range<double>("delay_s", fallback.delay_s, 0.0, 3600.0);
  b.code = config.get<std::string>("code", fallback.code);
  if (b.code.empty()) config.fail("code", "expected a non-empty failure code");
  b.message = config.get<std::string>("message", fallback.message);
  b.progress_steps = config.get_in_range<unsigned>("progress_steps", fallback.progress_steps, 0U, 1000U);
  b.stop_delay_s = config.get_in_range<double>("stop_delay_s", fallback.stop_delay_s, 0.0, 3600.0);
  b.never_stop = config.get<bool>("never_stop", fallback.never_stop);
  return b;
}

const char* to_string(Mode mode) {
  switch (mode) {
    case Mode::kSucceed: return "succeed";
    case Mode::kFail: return "fail";
    case Mode::kRun: return "run";
    case Mode::kCrash: return "crash";
    case Mode::kHang: return "hang";
  }
  return "succeed";
}

}  // namespace rigger::scripted
