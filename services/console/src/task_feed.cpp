#include "task_feed.hpp"

#include <algorithm>
#include <utility>
#include <vector>

#include "rigger/dds/conversions.hpp"
#include "rigger/dds/sequences.hpp"
#include "rigger/protocol/skill.hpp"
#include "rigger/protocol/task.hpp"
#include "rigger/protocol/task_names.hpp"

namespace rigger::console {

using nlohmann::json;

namespace {
double seconds(const rigger_geometry_Time& t) { return static_cast<double>(t.sec) + 1e-9 * t.nanosec; }
}  // namespace

TaskFeed::TaskFeed(const dds::Participant& participant, ConsoleState& state, SkillCatalog& skills)
    : state_(state),
      skills_(skills),
      task_status_(participant, protocol::task::kStatus),
      node_status_(participant, protocol::task::kNodeStatus, dds::qos::state_changes()),
      executors_(participant, protocol::skill::kExecutors, dds::qos::state()) {}

void TaskFeed::attach(dds::EventLoop& loop) {
  loop.on_data(task_status_, [this] { take_task_status(); });
  loop.on_data(node_status_, [this] { take_node_status(); });
  loop.on_data(executors_, [this] { take_executors(); });
}

std::array<dds_entity_t, 3> TaskFeed::readers() const {
  return {task_status_.handle(), node_status_.handle(), executors_.handle()};
}

void TaskFeed::take_task_status() {
  task_status_.take([this](const rigger_task_TaskStatus& s, const dds_sample_info_t&) {
    json errors = json::array();
    for (const auto& e : dds::elements(s.errors))
      errors.push_back({{"pointer", dds::to_string(e.pointer)}, {"message", dds::to_string(e.message)}});
    state_.update_task({{"task_id", dds::to_string(s.task_id)},
                        {"state", protocol::task::task_state_name(s.state)},
                        {"code", dds::to_string(s.code)},
                        {"message", dds::to_string(s.message)},
                        {"failed_node", dds::to_string(s.failed_node)},
                        {"errors", errors},
                        {"submitted", seconds(s.submitted)},
                        {"stamp", seconds(s.stamp)}});
    if (task_observer_)
      task_observer_(dds::to_string(s.task_id), protocol::task::task_state_name(s.state), seconds(s.stamp));
  });
}

void TaskFeed::take_node_status() {
  // A take groups samples by instance (node); the controller writes a burst (a child, then its parent)
  // together. In stamp order they read as they happened (as riggerctl run shows them).
  std::vector<std::pair<double, json>> changes;
  node_status_.take([&](const rigger_task_NodeStatus& s, const dds_sample_info_t&) {
    changes.emplace_back(seconds(s.stamp), json{{"task_id", dds::to_string(s.task_id)},
                                                {"node_id", dds::to_string(s.node_id)},
                                                {"parent_id", dds::to_string(s.parent_id)},
                                                {"type", dds::to_string(s.node_type)},
                                                {"name", dds::to_string(s.name)},
                                                {"state", protocol::task::node_state_name(s.state)},
                                                {"code", dds::to_string(s.code)},
                                                {"message", dds::to_string(s.message)},
                                                {"progress", s.progress},
                                                {"progress_text", dds::to_string(s.progress_text)},
                                                {"executor", dds::to_string(s.executor_id)},
                                                {"started", seconds(s.started)},
                                                {"finished", seconds(s.finished)},
                                                {"stamp", seconds(s.stamp)}});
  });
  std::stable_sort(changes.begin(), changes.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
  for (const auto& [stamp, node] : changes) state_.update_node(node);
}

void TaskFeed::take_executors() {
  executors_.take(
      [this](const rigger_skill_ExecutorAnnouncement& a, const dds_sample_info_t&) {
        json skills = json::array();
        for (const char* skill : dds::elements(a.skills)) skills.push_back(dds::to_string(skill));
        state_.update_executor({{"executor_id", dds::to_string(a.executor_id)}, {"host", dds::to_string(a.host)},
                                {"pid", a.pid}, {"skills", skills}, {"alive", true}});
        skills_.update(dds::to_string(a.executor_id), true, dds::to_string(a.library_json));
      },
      [this](const rigger_skill_ExecutorAnnouncement& key, const dds_sample_info_t& info) {
        if (info.instance_state != DDS_IST_ALIVE) {
          state_.update_executor({{"executor_id", dds::to_string(key.executor_id)}, {"alive", false}});
          skills_.update(dds::to_string(key.executor_id), false, "");
        }
      });
}

dds_return_t write_recipe(const dds::Writer<rigger_task_Recipe>& writer, const std::string& task_id,
                          const std::string& recipe_json, const std::string& submitter) {
  rigger_task_Recipe r{};
  r.task_id = dds::wire_string(task_id);
  r.recipe_json = dds::wire_string(recipe_json);
  r.submitter = dds::wire_string(submitter);
  r.stamp = dds::wire_now();
  return writer.write(r);
}

}  // namespace rigger::console
