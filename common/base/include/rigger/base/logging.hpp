#pragma once
/// @file
/// One named spdlog logger per process, handed to whoever logs (never spdlog's default logger).
/// Messages read "event key=value key=value".

#include <memory>
#include <string>

#include <spdlog/spdlog.h>

namespace rigger {

using Logger = std::shared_ptr<spdlog::logger>;

/// Creates the process's logger, writing to stderr with ISO timestamps. Thread-safe sink.
/// @throws std::invalid_argument when `level` is not one of trace, debug, info, warn, error, critical, off.
Logger make_logger(const std::string& name, const std::string& level = "info");

/// A logger that discards everything, for tests and libraries used without a process logger.
Logger null_logger();

}  // namespace rigger
