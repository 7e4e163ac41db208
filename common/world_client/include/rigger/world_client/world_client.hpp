#pragma once
/// @file
/// The client everyone uses to reach the world model: queries on `rigger/world/query` answered on
/// `rigger/world/reply`, pose updates on `rigger/world/update` answered on `rigger/world/update_result`.
/// Every request carries a correlation id (client_id + request_id); every request ends with exactly
/// one callback: the world model's answer, or ok=false with code "WORLD_UNREACHABLE" after the
/// timeout. A request made before a world model is matched waits for the match within that timeout
/// (discovery may be a round behind a service that has just started; checked every 20 ms on the
/// owner's EventLoop) and then says no world model was matched on its topic. A request unanswered after
/// kQueryResend is sent again (its answer may have been written before the world model had discovered
/// this client): a query is a read, and an update keeps its seq, by which the world model answers a
/// repeat with the result it had instead of applying it twice.
///
/// Thread safety: none. Construct, call and destroy on the owner's EventLoop thread (or before run());
/// callbacks run on that thread, never inside a call. The client must be destroyed before its loop.

#include <chrono>
#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <string>

#include <Eigen/Geometry>
#include <nlohmann/json.hpp>

#include "rigger/base/logging.hpp"
#include "rigger/base/time.hpp"
#include "rigger/dds/event_loop.hpp"
#include "rigger/dds/participant.hpp"
#include "rigger/dds/pubsub.hpp"
#include "rigger/world_protocol/world_protocol.hpp"

namespace rigger::world_client {

/// Code of a reply synthesised by the client: no world model answered in time (or none is matched).
inline constexpr const char* kUnreachable = "WORLD_UNREACHABLE";
/// How long a query or update waits for its answer before it is sent again.
inline constexpr std::chrono::milliseconds kQueryResend{500};
/// Code of a reply synthesised by the client: the world model's result_json did not parse.
inline constexpr const char* kBadReply = "BAD_REPLY";

/// The answer to one request. On ok=false, `code` (e.g. "UNKNOWN_ENTITY", "WORLD_UNREACHABLE") and
/// `message` say why and the other fields are unset.
struct Reply {
  bool ok = false;
  std::string code;     ///< "OK" when ok; for updates "ACCEPTED" or the rejection code ("STAMP_BACKWARDS", ...)
  std::string message;  ///< human-readable reason when !ok
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();  ///< pose(): T_frame_entity, m
  std::string frame;    ///< the frame `pose` is expressed in
  bool localized = false;  ///< pose(), is_localized(): the answer's localized flag
  double age_s = 0;        ///< pose(), is_localized(): age of the (oldest) pose used, s
  nlohmann::json result;   ///< query-specific JSON (features, entity description, list; update: revision)
};

/// Request/reply access to the world model (see the file comment).
class WorldClient {
 public:
  using Callback = std::function<void(const Reply&)>;

  /// `client_id` must be unique in the domain (replies are addressed to it), e.g. the process id.
  /// @throws DdsError when the topics cannot be created.
  WorldClient(const dds::Participant& participant, dds::EventLoop& loop, Logger log, std::string client_id);
  WorldClient(const WorldClient&) = delete;
  WorldClient& operator=(const WorldClient&) = delete;
  /// Cancels every pending request (their callbacks are not called).
  ~WorldClient();

  /// Is `entity` localized, with a pose no older than `max_age_s` (<= 0: any age)? ok=true whenever the
  /// world model answered; then `localized`, `age_s` and `code` ("LOCALIZED", "NOT_LOCALIZED", "STALE",
  /// "TOO_OLD", "NO_POSE") tell. Returns the request id.
  std::uint64_t is_localized(const std::string& entity, double max_age_s, std::chrono::milliseconds timeout, Callback cb);
  /// The pose of `entity` in `frame` through the frame tree.
  std::uint64_t pose(const std::string& entity, const std::string& frame, std::chrono::milliseconds timeout, Callback cb);
  /// The pose of feature `feature_id` (grasp frame, waypoint, screw hole, "rope_attachment") of `entity`
  /// in `frame`.
  std::uint64_t feature_pose(const std::string& entity, const std::string& feature_id, const std::string& frame,
                             std::chrono::milliseconds timeout, Callback cb);
  /// The CAD features of `entity` in `result` (the cell configuration's features format).
  std::uint64_t features(const std::string& entity, std::chrono::milliseconds timeout, Callback cb);
  /// The full description of `entity` in `result` (see world_json.hpp entity_to_json).
  std::uint64_t entity(const std::string& entity, std::chrono::milliseconds timeout, Callback cb);
  /// The ids of all entities (or, with `kind`, of the entities of that kind) in `result` (a JSON array of
  /// strings).
  std::uint64_t list(std::chrono::milliseconds timeout, Callback cb,
                     std::optional<world_protocol::EntityKind> kind = std::nullopt);

  /// Pose update (validated by the world model; ok=true with code "ACCEPTED" when applied, else ok=false
  /// with the rejection code). `pose` is T_parent_entity in `parent_frame` (re-parents when it differs
  /// from the current parent); `stamp` is the observation time; `quality` in [0, 1], negative: not given.
  std::uint64_t update_pose(const std::string& entity, const std::string& parent_frame, const Eigen::Isometry3d& pose,
                            WallTime stamp, double quality, bool localized, std::chrono::milliseconds timeout, Callback cb);
  /// Sets only the localized flag of `entity` (e.g. to mark it lost).
  std::uint64_t set_localized(const std::string& entity, bool localized, WallTime stamp, std::chrono::milliseconds timeout,
                              Callback cb);

  /// Forgets a pending request: its callback will not be called. Unknown ids are ignored.
  void cancel(std::uint64_t request_id);

  /// True when a world model's query reader and reply writer are matched.
  bool connected() const;
  /// Requests still waiting for an answer.
  std::size_t pending() const { return pending_.size(); }
  const std::string& client_id() const { return client_id_; }

 private:
  struct Pending {
    Callback callback;
    dds::EventLoop::TimerId timer = 0;
    dds::EventLoop::TimerId retry = 0;  ///< waiting for a world model to match (0: none)
    bool sent = false;
  };

  // A request is kept until a world model is matched (and, for a query, until answered): the wire sample
  // borrows its strings.
  std::uint64_t send_query(world_protocol::Query query, std::chrono::milliseconds timeout, Callback cb);
  std::uint64_t send_update(world_protocol::Update update, std::chrono::milliseconds timeout, Callback cb);
  void write_update(std::uint64_t id, std::shared_ptr<const world_protocol::Update> update);
  std::uint64_t track(std::chrono::milliseconds timeout, const char* topic, Callback cb);
  void write_query(std::uint64_t id, std::shared_ptr<const world_protocol::Query> query);
  void fail_soon(std::uint64_t request_id, const std::string& why);
  void finish(std::uint64_t request_id, const Reply& reply);
  void on_replies();
  void on_update_results();

  dds::EventLoop& loop_;
  Logger log_;
  std::string client_id_;
  dds::Writer<rigger_world_WorldQuery> queries_;
  dds::Reader<rigger_world_WorldReply> replies_;
  dds::Writer<rigger_world_EntityUpdate> updates_;
  dds::Reader<rigger_world_UpdateResult> update_results_;
  std::map<std::uint64_t, Pending> pending_;
  std::uint64_t next_request_id_ = 1;
};

}  // namespace rigger::world_client
