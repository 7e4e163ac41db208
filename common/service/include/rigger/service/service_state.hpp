#pragma once
/// @file
/// Readiness and liveness of rigger processes on rigger/system/service_state. Every service announces
/// STARTING, READY and STOPPING; the writer's liveliness lease makes a dead or hung process visible to
/// every ServiceDirectory within the lease (default 300 ms).

#include <chrono>
#include <map>
#include <string>
#include <vector>

#include "rigger/dds/pubsub.hpp"

namespace rigger::service {

/// How often a service re-announces its state (see ServiceAnnouncer::reannounce()).
inline constexpr std::chrono::milliseconds kServiceRefreshPeriod{1000};

enum class ServiceStatus { kStarting, kReady, kStopping, kFault };

/// Publishes this process's state. Thread-safe.
class ServiceAnnouncer {
 public:
  /// @throws DdsError.
  ServiceAnnouncer(const dds::Participant& participant, std::string service_id, std::string kind,
                   std::chrono::milliseconds lease = dds::liveliness_lease());
  /// Unregisters the instance, so readers see the service leave at once rather than after the lease.
  ~ServiceAnnouncer();
  ServiceAnnouncer(const ServiceAnnouncer&) = delete;
  ServiceAnnouncer& operator=(const ServiceAnnouncer&) = delete;

  /// Returns the DDS return code; never throws.
  dds_return_t announce(ServiceStatus status, const std::string& detail = "");
  /// Writes the last announced state again. Readers drop an instance whose writer missed its lease
  /// and only see it again on a new sample, so call this when the writer reports LIVELINESS_LOST
  /// (run_service does): a process that stalled and recovered is then visible again.
  dds_return_t reannounce();
  const std::string& service_id() const { return service_id_; }
  /// The last announced status (kStarting before the first announcement).
  ServiceStatus status() const { return last_status_; }
  /// The announcement writer, for its DDS_LIVELINESS_LOST_STATUS.
  dds_entity_t writer_handle() const { return writer_.handle(); }

 private:
  std::string service_id_;
  std::string kind_;
  std::string host_;
  ServiceStatus last_status_ = ServiceStatus::kStarting;
  std::string last_detail_;
  dds::Writer<rigger_system_ServiceState> writer_;
};

/// What a ServiceDirectory knows of one service.
struct ServiceInfo {
  std::string id;
  std::string kind;
  std::string host;
  std::string detail;
  int pid = 0;
  ServiceStatus status = ServiceStatus::kStarting;
  bool alive = false;  ///< false once it unregistered, disposed, or its liveliness lease expired
  std::chrono::steady_clock::time_point changed;  ///< when alive/status last changed, local steady clock
};

/// Tracks every service on the domain. Call update() when its reader has data (EventLoop::on_data).
class ServiceDirectory {
 public:
  /// @throws DdsError.
  explicit ServiceDirectory(const dds::Participant& participant);
  const dds::Reader<rigger_system_ServiceState>& reader() const { return reader_; }
  /// Takes pending samples; returns true when a service appeared, changed state, or was lost.
  bool update();
  const std::map<std::string, ServiceInfo>& services() const { return services_; }
  bool is_ready(const std::string& id) const;
  /// Ids of the services that are alive and READY, sorted.
  std::vector<std::string> ready_ids() const;

 private:
  dds::Reader<rigger_system_ServiceState> reader_;
  std::map<std::string, ServiceInfo> services_;
};

const char* to_string(ServiceStatus status);

}  // namespace rigger::service
