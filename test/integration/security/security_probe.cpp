// rigger_security_probe: a participant that tries what an intruder on the cell network would — submit
// a recipe, CANCEL a running task, command a crane velocity — and logs, for each, whether its writer
// was refused locally, how many readers matched it, and that it wrote anyway. Run with whatever
// CYCLONEDDS_URI / RIGGER_SECURITY_DIR / RIGGER_IDENTITY the attack needs (test/integration/security_test.cpp).
//
//   rigger_security_probe --domain D --label L --cancel TASK_ID [--match-window-ms N]
//
// Exit code 0 once every attempt was made (the test judges the cell, not the probe); 2 on a bad command
// line; 1 when it cannot even join the domain.
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <memory>
#include <string>

#include "rigger/dds/conversions.hpp"
#include "rigger/dds/entity.hpp"
#include "rigger/dds/participant.hpp"
#include "rigger/dds/pubsub.hpp"
#include "rigger/protocol/crane.hpp"
#include "rigger/protocol/task.hpp"

namespace {

using namespace rigger;

struct Options {
  long domain = -1;
  std::string label, cancel_task;
  long window_ms = 2000;
};

void say(const Options& o, const std::string& line) {
  std::printf("probe %s: %s\n", o.label.c_str(), line.c_str());
  std::fflush(stdout);
}

// Opens a writer on `topic`, waits up to the window for a reader to match, writes `sample` whatever the
// outcome. Returns the number of matched readers at write time (-1: the writer was refused).
template <typename T>
int attempt(const dds::Participant& participant, const protocol::Topic<T>& topic, const T& sample, const Options& o) {
  try {
    dds::Writer<T> writer(participant, topic);
    const bool matched = writer.wait_for_readers(1, std::chrono::milliseconds(o.window_ms));
    const dds_return_t rc = writer.write(sample);
    const auto readers = writer.matched_readers();
    say(o, std::string(topic.name) + ": " + (matched ? "MATCHED " : "no reader matched, ") +
               std::to_string(readers) + " reader(s); wrote it anyway: " + dds_strretcode(rc));
    return static_cast<int>(readers);
  } catch (const std::exception& e) {
    say(o, std::string(topic.name) + ": writer REFUSED locally: " + e.what());
    return -1;
  }
}

}  // namespace

int main(int argc, char** argv) {
  Options o;
  for (int i = 1; i + 1 < argc; i += 2) {
    const std::string k = argv[i], v = argv[i + 1];
    if (k == "--domain") o.domain = std::strtol(v.c_str(), nullptr, 10);
    else if (k == "--label") o.label = v;
    else if (k == "--cancel") o.cancel_task = v;
    else if (k == "--match-window-ms") o.window_ms = std::strtol(v.c_str(), nullptr, 10);
    else {
      std::fprintf(stderr, "rigger_security_probe: unknown option %s\n", k.c_str());
      return 2;
    }
  }
  if (o.domain < 0 || o.domain > 232 || o.label.empty() || o.cancel_task.empty() || o.window_ms < 0 ||
      o.window_ms > 60000) {
    std::fprintf(stderr, "usage: rigger_security_probe --domain D --label L --cancel TASK_ID [--match-window-ms N]\n");
    return 2;
  }
  const char* identity = std::getenv("RIGGER_IDENTITY");
  const char* uri = std::getenv("CYCLONEDDS_URI");
  say(o, std::string("joining domain ") + std::to_string(o.domain) + " as identity '" + (identity ? identity : "") +
             "' with " + (uri ? uri : "(no CYCLONEDDS_URI)"));
  std::unique_ptr<dds::Participant> participant;
  try {
    participant = std::make_unique<dds::Participant>(static_cast<std::uint32_t>(o.domain));
  } catch (const std::exception& e) {
    say(o, std::string("cannot join: ") + e.what());
    return 1;
  }

  const std::string cancel_issuer = "probe-" + o.label, reason = "intrusion test";
  rigger_task_TaskCommand cancel{};
  cancel.task_id = dds::wire_string(o.cancel_task);
  cancel.kind = rigger_task_TASK_CANCEL;
  cancel.reason = dds::wire_string(reason);
  cancel.issuer = dds::wire_string(cancel_issuer);
  cancel.seq = 1;
  cancel.stamp = dds::wire_now();
  attempt(*participant, protocol::task::kCommand, cancel, o);

  const std::string task_id = "attack-" + o.label;
  const std::string recipe_json =
      R"({"recipe_version": 1, "task_id": ")" + task_id +
      R"(", "root": {"type": "Skill", "name": "intruder", "skill": "Localize", "params": {"object": "load"}}})";
  rigger_task_Recipe recipe{};
  recipe.task_id = dds::wire_string(task_id);
  recipe.recipe_json = dds::wire_string(recipe_json);
  recipe.submitter = dds::wire_string(cancel_issuer);
  recipe.stamp = dds::wire_now();
  attempt(*participant, protocol::task::kRecipe, recipe, o);

  rigger_crane_CraneVelocityCommand velocity{};
  velocity.header.stamp = dds::wire_now();
  velocity.header.frame_id = dds::wire_string("world");
  velocity.seq = 1;
  velocity.velocity_mps[0] = 0.5;
  velocity.timeout_s = 0.5;
  velocity.source = dds::wire_string(cancel_issuer);
  attempt(*participant, protocol::crane::kCmdVelocity, velocity, o);
  say(o, "done");
  return 0;
}
