#pragma once
/// @file
/// The domain participant: declared first in every node so it is destroyed last.

#include <cstdint>

#include "rigger/dds/entity.hpp"

namespace rigger::dds {

/// Owns a DomainParticipant on `domain_id`. Cyclone reads its configuration from CYCLONEDDS_URI
/// (deploy/cyclonedds.xml for rigger). @throws DdsError on failure.
class Participant {
 public:
  explicit Participant(std::uint32_t domain_id);
  std::uint32_t domain_id() const { return domain_id_; }
  dds_entity_t handle() const { return entity_.handle(); }
  /// Asserts MANUAL_BY_PARTICIPANT liveliness of all this participant's writers. Thread-safe.
  void assert_liveliness() const;

 private:
  Entity entity_;
  std::uint32_t domain_id_;
};

/// The domain id from $RIGGER_DOMAIN, or `fallback`.
/// @throws std::invalid_argument when $RIGGER_DOMAIN is set but is not an integer in [0, 232].
std::uint32_t domain_from_environment(std::uint32_t fallback = 0);

}  // namespace rigger::dds
