#include "rigger/dds/pubsub.hpp"

namespace rigger::dds {

bool wait_for_status(dds_entity_t entity, uint32_t status, const std::function<bool()>& done,
                     std::chrono::nanoseconds timeout) {
  if (done()) return true;
  const dds_entity_t participant = dds_get_participant(entity);
  Entity waitset(dds_create_waitset(participant), "create waitset");
  check(dds_set_status_mask(entity, status), "set status mask");
  check(dds_waitset_attach(waitset.handle(), entity, 0), "attach to waitset");
  const dds_time_t deadline = dds_time() + timeout.count();
  while (!done()) {
    const dds_time_t now = dds_time();
    if (now >= deadline) break;
    dds_attach_t triggered;
    const auto n = dds_waitset_wait(waitset.handle(), &triggered, 1, deadline - now);
    if (n < 0) break;
    uint32_t ignored;
    dds_take_status(entity, &ignored, status);
  }
  dds_waitset_detach(waitset.handle(), entity);
  return done();
}

}  // namespace rigger::dds
