#include "rigger/dds/qos.hpp"

#include <utility>

#include "environment.hpp"

namespace rigger::dds {

Qos::Qos() : qos_(dds_create_qos()) {}
Qos::Qos(Qos&& other) noexcept : qos_(std::exchange(other.qos_, nullptr)) {}
Qos& Qos::operator=(Qos&& other) noexcept {
  if (this != &other) {
    if (qos_) dds_delete_qos(qos_);
    qos_ = std::exchange(other.qos_, nullptr);
  }
  return *this;
}
Qos::~Qos() {
  if (qos_) dds_delete_qos(qos_);
}

Qos& Qos::reliable(std::chrono::milliseconds max_blocking) {
  dds_qset_reliability(qos_, DDS_RELIABILITY_RELIABLE, DDS_MSECS(max_blocking.count()));
  return *this;
}
Qos& Qos::best_effort() {
  dds_qset_reliability(qos_, DDS_RELIABILITY_BEST_EFFORT, 0);
  return *this;
}
Qos& Qos::keep_last(int depth) {
  dds_qset_history(qos_, DDS_HISTORY_KEEP_LAST, depth);
  return *this;
}
Qos& Qos::keep_all() {
  dds_qset_history(qos_, DDS_HISTORY_KEEP_ALL, DDS_LENGTH_UNLIMITED);
  return *this;
}
Qos& Qos::volatile_durability() {
  dds_qset_durability(qos_, DDS_DURABILITY_VOLATILE);
  return *this;
}
Qos& Qos::transient_local() {
  dds_qset_durability(qos_, DDS_DURABILITY_TRANSIENT_LOCAL);
  return *this;
}
Qos& Qos::manual_liveliness(std::chrono::milliseconds lease) {
  dds_qset_liveliness(qos_, DDS_LIVELINESS_MANUAL_BY_PARTICIPANT, DDS_MSECS(lease.count()));
  return *this;
}

std::chrono::milliseconds liveliness_lease() {
  static const std::chrono::milliseconds lease = [] {
    const auto v = detail::integer_from_environment("RIGGER_LIVELINESS_LEASE_MS", 100, 10000,
                                                    "a liveliness lease in milliseconds");
    return v ? std::chrono::milliseconds(*v) : kDefaultLease;
  }();
  return lease;
}

namespace qos {
Qos commands() {
  Qos q;
  q.reliable().keep_all().volatile_durability();
  return q;
}
Qos events() {
  Qos q;
  q.reliable().keep_all().volatile_durability();
  return q;
}
Qos state() {
  Qos q;
  q.reliable().keep_last(1).transient_local();
  return q;
}
Qos state_changes(int depth) {
  Qos q;
  q.reliable().keep_last(depth).transient_local();
  return q;
}
Qos sensor_stream() {
  Qos q;
  q.best_effort().keep_last(1).volatile_durability();
  return q;
}
Qos setpoints() {
  Qos q;
  q.reliable().keep_last(1).volatile_durability();
  return q;
}
Qos announcements(std::chrono::milliseconds lease) {
  Qos q = state();
  q.manual_liveliness(lease);
  return q;
}
Qos of(protocol::QosProfile profile) {
  switch (profile) {
    case protocol::QosProfile::kCommands:
      return commands();
    case protocol::QosProfile::kEvents:
      return events();
    case protocol::QosProfile::kState:
      return state();
    case protocol::QosProfile::kAnnouncements:
      return announcements();
    case protocol::QosProfile::kSensorStream:
      return sensor_stream();
    case protocol::QosProfile::kSetpoints:
      return setpoints();
  }
  return commands();
}

}  // namespace qos

}  // namespace rigger::dds
