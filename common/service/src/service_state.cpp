#include "rigger/service/service_state.hpp"

#include <unistd.h>

#include "rigger/dds/conversions.hpp"
#include "rigger/protocol/system.hpp"

namespace rigger::service {
namespace {

rigger_system_ServiceStateKind to_wire(ServiceStatus s) {
  switch (s) {
    case ServiceStatus::kStarting: return rigger_system_SERVICE_STARTING;
    case ServiceStatus::kReady: return rigger_system_SERVICE_READY;
    case ServiceStatus::kStopping: return rigger_system_SERVICE_STOPPING;
    case ServiceStatus::kFault: return rigger_system_SERVICE_FAULT;
  }
  return rigger_system_SERVICE_FAULT;
}

ServiceStatus to_domain(rigger_system_ServiceStateKind s) {
  switch (s) {
    case rigger_system_SERVICE_STARTING: return ServiceStatus::kStarting;
    case rigger_system_SERVICE_READY: return ServiceStatus::kReady;
    case rigger_system_SERVICE_STOPPING: return ServiceStatus::kStopping;
    case rigger_system_SERVICE_FAULT: return ServiceStatus::kFault;
  }
  return ServiceStatus::kFault;
}

std::string host_name() {
  char buf[256] = {};
  if (gethostname(buf, sizeof buf - 1) != 0) return "unknown";
  return buf;
}

}  // namespace

const char* to_string(ServiceStatus status) {
  switch (status) {
    case ServiceStatus::kStarting: return "STARTING";
    case ServiceStatus::kReady: return "READY";
    case ServiceStatus::kStopping: return "STOPPING";
    case ServiceStatus::kFault: return "FAULT";
  }
  return "?";
}

ServiceAnnouncer::ServiceAnnouncer(const dds::Participant& participant, std::string service_id, std::string kind,
                                   std::chrono::milliseconds lease)
    : service_id_(std::move(service_id)),
      kind_(std::move(kind)),
      host_(host_name()),
      writer_(participant, protocol::system::kServiceState, dds::qos::announcements(lease)) {}

ServiceAnnouncer::~ServiceAnnouncer() {
  rigger_system_ServiceState key{};
  key.service_id = dds::wire_string(service_id_);
  key.kind = dds::wire_string(kind_);
  key.host = dds::wire_string(host_);
  key.detail = dds::wire_string("");
  writer_.unregister(key);
}

dds_return_t ServiceAnnouncer::reannounce() { return announce(last_status_, last_detail_); }

dds_return_t ServiceAnnouncer::announce(ServiceStatus status, const std::string& detail) {
  last_status_ = status;
  last_detail_ = detail;
  rigger_system_ServiceState s{};
  s.service_id = dds::wire_string(service_id_);
  s.kind = dds::wire_string(kind_);
  s.state = to_wire(status);
  s.pid = static_cast<int32_t>(getpid());
  s.host = dds::wire_string(host_);
  s.detail = dds::wire_string(detail);
  s.stamp = dds::wire_now();
  return writer_.write(s);
}

ServiceDirectory::ServiceDirectory(const dds::Participant& participant)
    : reader_(participant, protocol::system::kServiceState, dds::qos::state()) {}

bool ServiceDirectory::update() {
  bool changed = false;
  const auto now = std::chrono::steady_clock::now();
  reader_.take(
      [&](const rigger_system_ServiceState& s, const dds_sample_info_t& info) {
        auto& svc = services_[dds::to_string(s.service_id)];
        const bool alive = info.instance_state == DDS_IST_ALIVE;
        const auto status = to_domain(s.state);
        if (svc.alive != alive || svc.status != status || svc.id.empty()) {
          changed = true;
          svc.changed = now;
        }
        svc.id = dds::to_string(s.service_id);
        svc.kind = dds::to_string(s.kind);
        svc.host = dds::to_string(s.host);
        svc.detail = dds::to_string(s.detail);
        svc.pid = s.pid;
        svc.status = status;
        svc.alive = alive;
      },
      [&](const rigger_system_ServiceState& key, const dds_sample_info_t& info) {
        // Unregistered, disposed, or the writer's liveliness lease expired: the service is gone.
        auto it = services_.find(dds::to_string(key.service_id));
        if (it == services_.end() || info.instance_state == DDS_IST_ALIVE) return;
        if (it->second.alive) {
          it->second.alive = false;
          it->second.changed = now;
          changed = true;
        }
      });
  return changed;
}

bool ServiceDirectory::is_ready(const std::string& id) const {
  auto it = services_.find(id);
  return it != services_.end() && it->second.alive && it->second.status == ServiceStatus::kReady;
}

std::vector<std::string> ServiceDirectory::ready_ids() const {
  std::vector<std::string> out;
  for (const auto& [id, svc] : services_)
    if (svc.alive && svc.status == ServiceStatus::kReady) out.push_back(id);
  return out;
}

}  // namespace rigger::service
