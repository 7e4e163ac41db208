#pragma once
/// @file
/// What a scripted skill does once started. Pure data, parsed from configuration.
///
/// A behaviour object (every key optional):
///   "mode":           "succeed" | "fail" | "run" | "crash" | "hang"
///                     succeed: SUCCESS after delay_s; fail: FAILURE(code) after delay_s;
///                     run: never finishes by itself (a quiet monitor); crash: std::abort() after delay_s;
///                     hang: blocks the executor's event loop after delay_s, so its liveliness lapses
///                     while the process stays alive.
///   "delay_s":        number in [0, 3600], default 0.1
///   "code":           FAILURE code, default "SCRIPTED_FAILURE"
///   "message":        text sent with SUCCESS/FAILURE
///   "progress_steps": integer in [0, 1000]: PROGRESS reports spread over delay_s before the result
///   "stop_delay_s":   number in [0, 3600]: how long a SHUTDOWN takes before STOPPED, default 0
///   "never_stop":     boolean: ignore SHUTDOWN (the controller's stop timeout must escalate)

#include <string>

#include "rigger/base/config.hpp"

namespace rigger::scripted {

enum class Mode { kSucceed, kFail, kRun, kCrash, kHang };

struct Behaviour {
  Mode mode = Mode::kSucceed;
  double delay_s = 0.1;
  std::string code = "SCRIPTED_FAILURE";
  std::string message;
  unsigned progress_steps = 0;
  double stop_delay_s = 0.0;
  bool never_stop = false;
};

/// Reads a behaviour object; `fallback` supplies absent keys. @throws ConfigError naming the key.
Behaviour parse_behaviour(const Config& config, const Behaviour& fallback);

const char* to_string(Mode mode);

}  // namespace rigger::scripted
