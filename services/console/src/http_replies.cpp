#include "http_replies.hpp"

#include <chrono>
#include <memory>

#include <httplib.h>

namespace rigger::console {

using nlohmann::json;

namespace {

constexpr std::size_t kMaxEventsPerWrite = 512;
constexpr std::chrono::milliseconds kKeepAlive{15000};

// The SSE frames of a batch: "id", "event" and "data" lines; a reset tells the client to reload the state.
std::string sse_frames(const EventLog& log, const EventBatch& batch) {
  std::string out;
  if (batch.reset) out += "id: " + log.id_of(batch.last_seq) + "\nevent: reset\ndata: {}\n\n";
  for (const auto& e : batch.events) out += "id: " + log.id_of(e.seq) + "\nevent: " + e.type + "\ndata: " + e.data + "\n\n";
  return out;
}

}  // namespace

std::string to_text(const json& j) { return j.dump(-1, ' ', false, json::error_handler_t::replace); }

void send_error(httplib::Response& res, int status, const std::string& error, const std::string& where) {
  res.status = status;
  res.set_content(to_text(json{{"error", error}, {"where", where}}), kJson);
}

void send_json(httplib::Response& res, const json& body, int status) {
  res.status = status;
  res.set_content(to_text(body), kJson);
}

std::string text_field(const json& body, const char* key) {
  const auto it = body.find(key);
  return it != body.end() && it->is_string() ? it->get<std::string>() : "";
}

std::shared_ptr<void> StreamSlots::take() {
  if (open_.fetch_add(1) >= max_) {
    open_.fetch_sub(1);
    return nullptr;
  }
  return std::shared_ptr<int>(new int(0), [this](int* p) {
    delete p;
    open_.fetch_sub(1);
  });
}

void stream_events(EventLog& log, const httplib::Request& req, httplib::Response& res, std::uint64_t start,
                   StreamSlots& slots, std::shared_ptr<void> hold) {
  std::shared_ptr<void> slot = slots.take();
  if (!slot) {
    res.set_header("Retry-After", "5");
    return send_error(res, 503,
                      "the console serves at most " + std::to_string(slots.max()) +
                          " live streams at once (max_streams): close a page or raise max_streams",
                      req.path);
  }
  std::string last = req.get_header_value("Last-Event-ID");
  if (last.empty() && req.has_param("last_event_id")) last = req.get_param_value("last_event_id");
  auto from = std::make_shared<std::uint64_t>(start);
  auto reset = std::make_shared<bool>(false);
  if (!last.empty()) {
    if (const auto seq = log.parse_id(last)) *from = *seq;
    else *reset = true;  // an id of an earlier run of the console: the client reloads the state
  }
  res.set_header("Cache-Control", "no-store");
  res.set_header("X-Accel-Buffering", "no");
  res.set_chunked_content_provider("text/event-stream", [&log, from, reset, slot, hold](std::size_t, httplib::DataSink& sink) {
    if (log.closed()) return false;
    std::string out;
    if (*reset) {
      *reset = false;
      *from = log.last_seq();
      out = "retry: 1000\nid: " + log.id_of(*from) + "\nevent: reset\ndata: {}\n\n";
    } else {
      const EventBatch batch = log.wait_after(*from, kMaxEventsPerWrite, kKeepAlive);
      if (log.closed()) return false;
      *from = batch.last_seq;
      out = batch.events.empty() && !batch.reset ? std::string(": keep-alive\n\n") : sse_frames(log, batch);
    }
    return sink.is_writable() && sink.write(out.data(), out.size());
  });
}

}  // namespace rigger::console
