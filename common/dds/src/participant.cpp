#include "rigger/dds/participant.hpp"

namespace rigger::dds {

Participant::Participant(std::uint32_t domain_id)
    : entity_(dds_create_participant(domain_id, nullptr, nullptr),
              "create participant (check CYCLONEDDS_URI and the domain id)"),
      domain_id_(domain_id) {}

void Participant::assert_liveliness() const { dds_assert_liveliness(entity_.handle()); }

}  // namespace rigger::dds
