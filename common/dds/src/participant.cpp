#include "rigger/dds/participant.hpp"

#include "environment.hpp"
#include "rigger/dds/configuration.hpp"

namespace rigger::dds {

namespace {
// Runs before dds_create_participant in the member initialiser list: the configuration must be in
// CYCLONEDDS_URI when Cyclone creates the domain.
dds_entity_t create_participant(std::uint32_t domain_id) {
  configuration();
  return dds_create_participant(domain_id, nullptr, nullptr);
}
}  // namespace

Participant::Participant(std::uint32_t domain_id)
    : entity_(create_participant(domain_id), ("create participant on " + describe_domain(domain_id)).c_str()),
      domain_id_(domain_id) {}

void Participant::assert_liveliness() const { dds_assert_liveliness(entity_.handle()); }

std::uint32_t domain_from_environment(std::uint32_t fallback) {
  const auto v = detail::integer_from_environment("RIGGER_DOMAIN", 0, 232, "a domain id");
  return v ? static_cast<std::uint32_t>(*v) : fallback;
}

}  // namespace rigger::dds
