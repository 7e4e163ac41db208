// `riggerctl topics` and `riggerctl echo TOPIC`: rigger's `ros2 topic list/echo/hz`, on the protocol
// catalog (every topic's type descriptor and QoS profile) and Cyclone's built-in discovery topics.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <deque>
#include <map>
#include <memory>
#include <set>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "commands.hpp"
#include "rigger/base/time.hpp"
#include "rigger/dds/event_loop.hpp"
#include "rigger/dds/pubsub.hpp"
#include "rigger/dds/sample_json.hpp"
#include "rigger/protocol/catalog.hpp"
#include "rigger/protocol/system.hpp"

namespace rigger::ctl {
namespace {

constexpr int kExitNoWriter = 1;
constexpr int kExitUsage = 2;

// ------------------------------------------------------------------------------------------ topics

struct TopicsOptions {
  bool json = false;
  double timeout_s = 1.0;
};

std::string guid_text(const dds_guid_t& g) {
  char buf[40];
  for (int i = 0; i < 12; ++i) std::snprintf(buf + 2 * i, 3, "%02x", g.v[i]);
  return std::string(buf, 24);
}

bool same_participant(const dds_guid_t& a, const dds_guid_t& b) {
  return std::equal(a.v, a.v + 12, b.v);
}

// One endpoint seen on the wire.
struct Endpoint {
  std::string topic, type;
  dds_guid_t participant{};
  dds_instance_handle_t handle = 0;
  bool writer = false;
};

// The built-in topics DCPSPublication and DCPSSubscription, read into `endpoints` (keyed by instance
// handle: a lost endpoint is removed).
class Discovery {
 public:
  explicit Discovery(const dds::Participant& participant)
      : publications_(dds_create_reader(participant.handle(), DDS_BUILTIN_TOPIC_DCPSPUBLICATION, nullptr, nullptr),
                      "create DCPSPublication reader"),
        subscriptions_(dds_create_reader(participant.handle(), DDS_BUILTIN_TOPIC_DCPSSUBSCRIPTION, nullptr, nullptr),
                       "create DCPSSubscription reader") {}
  dds_entity_t publications() const { return publications_.handle(); }
  dds_entity_t subscriptions() const { return subscriptions_.handle(); }

  void update(dds_entity_t reader) {
    const bool writer = reader == publications_.handle();
    constexpr int kBatch = 64;
    for (;;) {
      void* buf[kBatch] = {};
      dds_sample_info_t info[kBatch];
      const int32_t n = dds_take(reader, buf, info, kBatch, kBatch);
      if (n <= 0) return;
      dds::LoanGuard guard(reader, buf, n);
      for (int32_t i = 0; i < n; ++i) {
        if (!info[i].valid_data || info[i].instance_state != DDS_IST_ALIVE) {
          endpoints_.erase(info[i].instance_handle);
          continue;
        }
        const auto* ep = static_cast<const dds_builtintopic_endpoint_t*>(buf[i]);
        Endpoint e;
        e.topic = ep->topic_name ? ep->topic_name : "";
        e.type = ep->type_name ? ep->type_name : "";
        std::copy(ep->participant_key.v, ep->participant_key.v + 16, e.participant.v);
        e.handle = info[i].instance_handle;
        e.writer = writer;
        endpoints_[e.handle] = e;
      }
      if (n < kBatch) return;
    }
  }
  const std::map<dds_instance_handle_t, Endpoint>& endpoints() const { return endpoints_; }

 private:
  dds::Entity publications_;
  dds::Entity subscriptions_;
  std::map<dds_instance_handle_t, Endpoint> endpoints_;
};

struct TopicRow {
  std::string name, type, qos;
  bool in_catalog = true;
  std::vector<std::string> writers, readers;  // who: a service id, or "participant <guid>"
};

std::string who_text(const std::vector<std::string>& who) {
  std::map<std::string, int> counted;
  for (const auto& w : who) ++counted[w];
  std::string out;
  for (const auto& [w, n] : counted) out += (out.empty() ? "" : ", ") + w + (n > 1 ? " ×" + std::to_string(n) : "");
  return out;
}

int run_topics(const CommonOptions& common, const TopicsOptions& opt) {
  dds::Participant participant(common.domain);
  dds_guid_t self{};
  dds_get_guid(participant.handle(), &self);
  dds::EventLoop loop(participant);
  Discovery discovery(participant);
  // Which service each participant is: the writer of its rigger/system/service_state announcement.
  dds::Reader<rigger_system_ServiceState> announcements(participant, protocol::system::kServiceState,
                                                        dds::qos::state());
  std::map<dds_instance_handle_t, std::string> service_of_writer;
  loop.on_data(discovery.publications(), [&] { discovery.update(discovery.publications()); });
  loop.on_data(discovery.subscriptions(), [&] { discovery.update(discovery.subscriptions()); });
  loop.on_data(announcements, [&] {
    announcements.take([&](const rigger_system_ServiceState& s, const dds_sample_info_t& info) {
      service_of_writer[info.publication_handle] = s.service_id ? s.service_id : "";
    });
  });
  // Discovery has no end to wait for: listen for the bounded time, as `ros2 topic list` does.
  loop.run_until([] { return false; }, from_seconds(opt.timeout_s));

  std::map<std::string, std::string> service_of_participant;  // guid text -> service id
  for (const auto& [handle, e] : discovery.endpoints()) {
    const auto it = service_of_writer.find(handle);
    if (e.writer && it != service_of_writer.end()) service_of_participant[guid_text(e.participant)] = it->second;
  }
  std::vector<TopicRow> rows;
  std::map<std::string, std::size_t> row_of;
  for (const auto& t : protocol::catalog()) {
    row_of[t.name] = rows.size();
    rows.push_back({t.name, t.idl_type, protocol::to_string(t.qos), true, {}, {}});
  }
  for (const auto& [handle, e] : discovery.endpoints()) {
    if (same_participant(e.participant, self)) continue;  // this command's own readers
    if (e.topic.rfind("DCPS", 0) == 0) continue;
    auto it = row_of.find(e.topic);
    if (it == row_of.end()) {
      it = row_of.emplace(e.topic, rows.size()).first;
      rows.push_back({e.topic, e.type, "", false, {}, {}});
    }
    const auto svc = service_of_participant.find(guid_text(e.participant));
    const std::string who =
        svc != service_of_participant.end() ? svc->second : "participant " + guid_text(e.participant);
    (e.writer ? rows[it->second].writers : rows[it->second].readers).push_back(who);
  }

  if (opt.json) {
    nlohmann::json out = {{"domain", common.domain}, {"topics", nlohmann::json::array()}};
    for (const auto& r : rows) {
      out["topics"].push_back({{"name", r.name},
                               {"type", r.type},
                               {"qos", r.in_catalog ? nlohmann::json(r.qos) : nlohmann::json(nullptr)},
                               {"in_catalog", r.in_catalog},
                               {"writers", r.writers},
                               {"readers", r.readers}});
    }
    std::printf("%s\n", out.dump().c_str());
  } else {
    std::printf("%-28s %-36s %-13s %s\n", "TOPIC", "TYPE", "QOS", "WRITERS / READERS");
    for (const auto& r : rows) {
      std::printf("%-28s %-36s %-13s %zu / %zu", r.name.c_str(), r.type.c_str(),
                  r.in_catalog ? r.qos.c_str() : "(not in the catalog)", r.writers.size(), r.readers.size());
      if (!r.writers.empty()) std::printf("  writers: %s", who_text(r.writers).c_str());
      if (!r.readers.empty()) std::printf("  readers: %s", who_text(r.readers).c_str());
      std::printf("\n");
    }
  }
  std::size_t live = 0;
  for (const auto& r : rows) live += r.writers.size() + r.readers.size();
  if (live == 0)
    std::fprintf(stderr, "riggerctl: no writer or reader seen on %s within %.1f s\n",
                 dds::describe_domain(common.domain).c_str(), opt.timeout_s);
  return 0;
}

// -------------------------------------------------------------------------------------------- echo

constexpr std::size_t kMaxCount = 1000000;

struct EchoOptions {
  std::string topic;
  std::size_t count = 0;  // 0: until interrupted (or --duration)
  double timeout_s = 5.0;
  double duration_s = 0;
  bool json = false;
  bool hz = false;
  std::size_t window = 100;
  dds::FormatLimits limits;
};

/// The reader side of a topic's profile for a tool that shows every sample: the profile's reliability
/// and durability (so it matches every writer, and a transient-local topic gives its latest state at
/// once), a deeper keep-last history so that a burst is not collapsed, and default liveliness (an
/// announcements reader requesting the services' lease would refuse a writer offering a longer one).
dds::Qos echo_qos(protocol::QosProfile profile) {
  dds::Qos q;
  switch (profile) {
    case protocol::QosProfile::kSensorStream:
      q.best_effort().volatile_durability();
      break;
    case protocol::QosProfile::kState:
    case protocol::QosProfile::kAnnouncements:
      q.reliable().transient_local();
      break;
    case protocol::QosProfile::kCommands:
    case protocol::QosProfile::kEvents:
    case protocol::QosProfile::kSetpoints:
      q.reliable().volatile_durability();
      break;
  }
  q.keep_last(256);
  return q;
}

/// Arrival times over a sliding window; the rate as `ros2 topic hz` prints it.
class RateWindow {
 public:
  explicit RateWindow(std::size_t size) : size_(std::max<std::size_t>(size, 2)) {}
  void add(std::chrono::steady_clock::time_point t) {
    arrivals_.push_back(t);
    if (arrivals_.size() > size_ + 1) arrivals_.pop_front();
  }
  /// "average rate: 20.001 Hz  min 0.049 s  max 0.051 s  std dev 0.00041 s  window 100", or JSON.
  bool report(bool json, std::string& out) const {
    if (arrivals_.size() < 2) return false;
    std::vector<double> gaps;
    for (std::size_t i = 1; i < arrivals_.size(); ++i)
      gaps.push_back(std::chrono::duration<double>(arrivals_[i] - arrivals_[i - 1]).count());
    double mean = 0;
    for (const double g : gaps) mean += g;
    mean /= static_cast<double>(gaps.size());
    double var = 0;
    for (const double g : gaps) var += (g - mean) * (g - mean);
    const double sd = std::sqrt(var / static_cast<double>(gaps.size()));
    const double rate = mean > 0 ? 1.0 / mean : 0;
    const auto [lo, hi] = std::minmax_element(gaps.begin(), gaps.end());
    char buf[256];
    if (json)
      std::snprintf(buf, sizeof buf, R"({"rate_hz":%.6g,"min_s":%.6g,"max_s":%.6g,"std_dev_s":%.6g,"window":%zu})",
                    rate, *lo, *hi, sd, gaps.size());
    else
      std::snprintf(buf, sizeof buf, "average rate: %.3f Hz  min %.4f s  max %.4f s  std dev %.5f s  window %zu", rate,
                    *lo, *hi, sd, gaps.size());
    out = buf;
    return true;
  }

 private:
  std::size_t size_;
  std::deque<std::chrono::steady_clock::time_point> arrivals_;
};

int run_echo(const CommonOptions& common, const EchoOptions& opt) {
  const protocol::TopicInfo* topic = protocol::find_topic(opt.topic);
  if (topic == nullptr) {
    const auto close = protocol::close_topic_names(opt.topic);
    std::string hint;
    for (const auto& c : close) hint += (hint.empty() ? "" : ", ") + c;
    std::fprintf(stderr, "riggerctl echo: unknown topic '%s'%s%s%s; `riggerctl topics` lists every topic\n",
                 opt.topic.c_str(), close.empty() ? "" : " (did you mean ", hint.c_str(), close.empty() ? "" : "?)");
    return kExitUsage;
  }
  const dds::SampleFormat format(*topic->descriptor);
  dds::Participant participant(common.domain);
  const dds::Entity dds_topic(
      dds_create_topic(participant.handle(), topic->descriptor, topic->name.c_str(), nullptr, nullptr),
      ("create topic " + topic->name).c_str());
  const dds::Qos qos = echo_qos(topic->qos);
  const dds::Entity reader(dds_create_reader(participant.handle(), dds_topic.handle(), qos.get(), nullptr),
                           ("create reader " + topic->name).c_str());
  const auto matched_writers = [&] {
    dds_subscription_matched_status_t st{};
    dds_get_subscription_matched_status(reader.handle(), &st);
    return st.current_count;
  };
  if (!dds::wait_for_status(
          reader.handle(), DDS_SUBSCRIPTION_MATCHED_STATUS, [&] { return matched_writers() > 0; },
          from_seconds(opt.timeout_s))) {
    std::fprintf(stderr, "riggerctl echo: no writer of %s (%s, %s QoS) on %s within %.1f s\n", topic->name.c_str(),
                 topic->idl_type.c_str(), protocol::to_string(topic->qos), dds::describe_domain(common.domain).c_str(),
                 opt.timeout_s);
    return kExitNoWriter;
  }

  dds::EventLoop loop(participant);
  std::size_t received = 0;
  RateWindow rate(opt.window);
  std::string line;
  loop.on_data(reader.handle(), [&] {
    constexpr int kBatch = 32;
    for (;;) {
      void* buf[kBatch] = {};
      dds_sample_info_t info[kBatch];
      const int32_t n = dds_take(reader.handle(), buf, info, kBatch, kBatch);
      if (n <= 0) return;
      dds::LoanGuard guard(reader.handle(), buf, n);
      const auto now = std::chrono::steady_clock::now();
      for (int32_t i = 0; i < n; ++i) {
        if (!info[i].valid_data) continue;  // disposed / no writers: not a sample
        if (opt.count && received >= opt.count) return;
        ++received;
        if (opt.hz) {
          rate.add(now);
        } else if (opt.json) {
          std::printf("%s\n", format.to_json(buf[i], opt.limits).c_str());
        } else {
          std::printf("%s---\n", format.to_text(buf[i], opt.limits).c_str());
        }
      }
      std::fflush(stdout);
      if (n < kBatch) return;
    }
  });
  if (opt.hz) {
    loop.every(std::chrono::seconds(1), [&] {
      if (rate.report(opt.json, line)) {
        std::printf("%s\n", line.c_str());
      } else if (!opt.json) {
        std::printf("no new samples\n");
      }
      std::fflush(stdout);
    });
  }
  const auto forever = std::chrono::hours(24 * 365);
  const auto limit = opt.duration_s > 0
                         ? std::chrono::duration_cast<std::chrono::nanoseconds>(from_seconds(opt.duration_s))
                         : std::chrono::duration_cast<std::chrono::nanoseconds>(forever);
  loop.run_until([&] { return opt.count && received >= opt.count; }, limit);
  if (opt.hz && rate.report(opt.json, line) && opt.count) std::printf("%s\n", line.c_str());
  return 0;
}

}  // namespace

void add_topic_commands(CLI::App& app, const CommonOptions& common, int& exit_code) {
  auto topics = std::make_shared<TopicsOptions>();
  auto* list = app.add_subcommand("topics", "List every topic with its type, QoS and the live writers/readers");
  list->add_flag("--json", topics->json,
                 "One JSON document: {domain, topics: [{name, type, qos, in_catalog, "
                 "writers, readers}]}");
  list->add_option("--timeout", topics->timeout_s, "Seconds to listen for discovery (default 1)")
      ->check(CLI::Range(0.0, 60.0));
  list->callback([&common, &exit_code, topics] { exit_code = run_topics(common, *topics); });

  auto echo = std::make_shared<EchoOptions>();
  auto* cmd = app.add_subcommand("echo", "Print the samples of a topic (any topic of `riggerctl topics`)");
  cmd->add_option("TOPIC", echo->topic, "e.g. rigger/crane/state")->required();
  cmd->add_option("--count", echo->count, "Exit after N samples (default: until interrupted)")
      ->check(CLI::Range(std::size_t{1}, kMaxCount));
  cmd->add_option("--timeout", echo->timeout_s, "Seconds to wait for a writer (default 5)")
      ->check(CLI::Range(0.0, 3600.0));
  cmd->add_option("--duration", echo->duration_s, "Exit after S seconds (default: no limit)")
      ->check(CLI::Range(0.0, 31536000.0));
  cmd->add_flag("--json", echo->json, "One JSON object per sample and line (field names as in the IDL)");
  cmd->add_flag("--hz", echo->hz, "Print the receive rate once a second instead of the samples");
  cmd->add_option("--window", echo->window, "Samples the rate is averaged over (default 100)")
      ->check(CLI::Range(std::size_t{2}, std::size_t{100000}));
  cmd->add_option("--max-elements", echo->limits.max_elements, "Elements shown per sequence/array (default 64)")
      ->check(CLI::Range(std::size_t{0}, std::size_t{1000000}));
  cmd->add_option("--max-string", echo->limits.max_string, "Bytes shown per string (default 1024)")
      ->check(CLI::Range(std::size_t{0}, std::size_t{1000000}));
  cmd->callback([&common, &exit_code, echo] { exit_code = run_echo(common, *echo); });
}

}  // namespace rigger::ctl
