#pragma once
/// @file
/// What the console's HTTP routes answer with: JSON bodies and errors, and Server-Sent Event streams of
/// an EventLog. Used by HttpApi's handlers only.
#include <atomic>
#include <cstdint>
#include <memory>
#include <string>

#include <nlohmann/json.hpp>

#include "event_log.hpp"

namespace httplib {
struct Request;
struct Response;
}

namespace rigger::console {

// Content types chosen so that cpp-httplib does not compress: 0.11 compresses with brotli at quality 11
// whenever the browser accepts br (every browser does) and the type is in its exact list (text/*,
// application/json, application/javascript): that cost 1.8 s of CPU per page load for three.js and
// 0.5 s per validation of a 1,000-node tree (bench_planner_tree); gzip would be 36 ms, but the library
// prefers br and gives no way to choose. The console serves a LAN, where the bytes cost less than that:
// JSON and JavaScript go uncompressed (three.js, 1.3 MB, in 2 ms on loopback). See docs/console.md.
constexpr const char* kJson = "application/json; charset=utf-8";
constexpr const char* kJavaScript = "application/javascript; charset=utf-8";

/// `j` as compact text. Strings from DDS or from requests are not checked for UTF-8: what is not is
/// replaced, never thrown on.
std::string to_text(const nlohmann::json& j);

/// Answers `status` with {"error": error, "where": where}.
void send_error(httplib::Response& res, int status, const std::string& error, const std::string& where);

/// Answers `status` with `body`.
void send_json(httplib::Response& res, const nlohmann::json& body, int status = 200);

/// `body[key]` when it is a string, else "".
std::string text_field(const nlohmann::json& body, const char* key);

/// The live streams open at once, bounded: each holds one of the HTTP server's worker threads until it
/// ends, and the requests of every page must still find a free one. Thread-safe.
class StreamSlots {
 public:
  explicit StreamSlots(int max) : max_(max) {}
  /// A slot, held until the returned handle is dropped; empty when all `max` are taken.
  std::shared_ptr<void> take();
  int open() const { return open_.load(); }
  int max() const { return max_; }

 private:
  std::atomic<int> open_{0};
  int max_;
};

/// Streams `log` as Server-Sent Events from the client's Last-Event-ID (header, or last_event_id in
/// the query), or from `start` when it has none, in one of `slots` (503 when none is free). The stream
/// ends when `log` is closed. `hold` is kept as long as the stream is open (a watcher count's guard).
void stream_events(EventLog& log, const httplib::Request& req, httplib::Response& res, std::uint64_t start,
                   StreamSlots& slots, std::shared_ptr<void> hold = nullptr);

}  // namespace rigger::console
