#include "rehearsal_link.hpp"

#include "rigger/protocol/task.hpp"

namespace rigger::console {

namespace {
constexpr std::size_t kEventCapacity = 50000;  // a rehearsal is one task at a time
}  // namespace

RehearsalLink::RehearsalLink(std::uint32_t domain_id, dds::EventLoop& loop, const std::string& epoch)
    : participant_(domain_id),
      loop_(loop),
      events_(kEventCapacity, epoch),
      state_(events_),
      tasks_(participant_, state_, skills_),
      recipes_(participant_, protocol::task::kRecipe) {
  dds_listener_t* listener = dds_create_listener(this);
  dds_lset_data_available(listener, [](dds_entity_t, void* self) { static_cast<RehearsalLink*>(self)->wake(); });
  for (const dds_entity_t reader : tasks_.readers()) dds_set_listener(reader, listener);
  dds_delete_listener(listener);
  wake();  // samples that arrived before the listeners were set
}

RehearsalLink::~RehearsalLink() {
  // dds_set_listener waits for a callback in progress: none runs once this returns. Work already posted
  // to the loop never runs: the console is destroyed after its loop ended.
  for (const dds_entity_t reader : tasks_.readers()) dds_set_listener(reader, nullptr);
  events_.close();
}

void RehearsalLink::wake() {
  if (!wake_pending_.exchange(true)) loop_.post([this] { take(); });
}

void RehearsalLink::take() {
  wake_pending_ = false;  // before taking: samples arriving meanwhile wake the loop again
  tasks_.take_task_status();
  tasks_.take_node_status();
  tasks_.take_executors();
}

ActionResult RehearsalLink::publish(const std::string& task_id, const std::string& recipe_json,
                                    const std::string& submitter) {
  const std::string domain = std::to_string(participant_.domain_id());
  if (recipes_.matched_readers() == 0)
    return {false, "no task controller reads recipes on the rehearsal domain " + domain +
                       " (is the rehearsal cell running? RIGGER_DOMAIN=" + domain + " deploy/rigger-compose up); nothing was sent",
            {}};
  const dds_return_t rc = write_recipe(recipes_, task_id, recipe_json, submitter);
  return {rc == DDS_RETCODE_OK, rc == DDS_RETCODE_OK ? "" : std::string("publishing failed: ") + dds_strretcode(rc), {}};
}

}  // namespace rigger::console
