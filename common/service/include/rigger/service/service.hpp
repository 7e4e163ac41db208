#pragma once
/// @file
/// The life of every rigger process, so that each service's main() is five lines:
///
///   int main(int argc, char** argv) {
///     return rigger::service::run_service(argc, argv, {"echo", "Answers rigger/echo/request.", {},
///         [](rigger::service::ServiceContext& ctx) { return std::make_unique<rigger::echo::EchoNode>(ctx); }});
///   }
///
/// run_service parses the common options (--id, --domain, --config, --log-level), sets up the logger,
/// creates the participant and the event loop, announces STARTING, builds the node, announces READY,
/// runs the loop until SIGINT/SIGTERM, announces STOPPING and destroys the node (whose destructor
/// brings its devices to a safe state). It asserts the participant's liveliness from a thread of its
/// own (LivelinessAsserter) every third of the shortest lease the participant's writers offer
/// (ServiceContext::offer_liveliness_lease), while the loop shows progress: a killed process is seen
/// by others within the lease, a hung loop within dds::kLoopStallLimit plus the lease.
///
/// Exit codes: 0 clean stop; 1 runtime failure; 2 bad command line or configuration.

#include <algorithm>
#include <chrono>
#include <functional>
#include <memory>
#include <optional>
#include <string>

#include <CLI/CLI.hpp>

#include "rigger/base/config.hpp"
#include "rigger/base/logging.hpp"
#include "rigger/dds/event_loop.hpp"
#include "rigger/dds/participant.hpp"
#include "rigger/dds/qos.hpp"
#include "rigger/service/service_state.hpp"

namespace rigger::service {

inline constexpr int kExitOk = 0;
inline constexpr int kExitFailure = 1;
inline constexpr int kExitUsage = 2;

/// A service's DDS node. Its destructor must leave its devices safe.
class Node {
 public:
  virtual ~Node() = default;
};

struct ServiceOptions {
  std::string id;           ///< unique per domain; defaults to the service kind
  std::uint32_t domain = 0;  ///< --domain, else $RIGGER_DOMAIN, else 0
  std::string config_path;  ///< --config; empty: defaults only
  std::string log_level = "info";
};

/// What a node gets to build itself. Lives for the whole run.
struct ServiceContext {
  const ServiceOptions& options;
  Logger log;
  dds::Participant& participant;
  dds::EventLoop& loop;
  ServiceAnnouncer& announcer;
  Config config;  ///< the --config file (or empty); the node calls config.finish() after reading it
  /// The shortest MANUAL_BY_PARTICIPANT liveliness lease this participant's writers offer: the service
  /// announcer's (dds::liveliness_lease()) unless the node offers a shorter one.
  std::chrono::milliseconds liveliness_lease = dds::liveliness_lease();

  /// A writer of the node offers `lease` (MANUAL_BY_PARTICIPANT): run_service asserts the participant's
  /// liveliness every third of the shortest lease offered. Call while the node is built.
  void offer_liveliness_lease(std::chrono::milliseconds lease) {
    liveliness_lease = std::min(liveliness_lease, lease);
  }
};

struct ServiceSpec {
  std::string kind;
  std::string description;
  /// Adds service-specific command-line options (optional).
  std::function<void(CLI::App&)> add_options;
  /// Builds the node. Throw ConfigError for bad configuration (exit 2), anything else for exit 1.
  std::function<std::unique_ptr<Node>(ServiceContext&)> make_node;
};

int run_service(int argc, char** argv, const ServiceSpec& spec);

}  // namespace rigger::service
