// The scripted operator with its shipped configuration (deploy/config/scripted_operator.json) answers
// the real task controller's OperatorDecision prompt: the demo's human in the loop, end to end.
#include <fstream>
#include <map>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "rigger/dds/conversions.hpp"
#include "rigger/dds/pubsub.hpp"
#include "rigger/protocol/operator.hpp"
#include "rigger/protocol/task.hpp"
#include "rigger/testing/cell.hpp"
#include "task_controller_node.hpp"

namespace rigger::testing {
namespace {

using namespace std::chrono_literals;
namespace tc = rigger::task_controller;

class OperatorTaskTest : public MultiProcessTest {
 protected:
  std::string write_config(const std::string& name, const nlohmann::json& config) {
    const std::string path = cell_.log_dir() + "/" + name + ".json";
    std::ofstream(path) << config.dump(2);
    return path;
  }
};

TEST_F(OperatorTaskTest, ShippedScriptedOperatorAnswersTheControllersDecision) {
  auto& p = cell_.participant();
  dds::Writer<rigger_task_Recipe> recipes(p, protocol::task::kRecipe);
  dds::Reader<rigger_task_TaskStatus> statuses(p, protocol::task::kStatus);
  dds::Reader<rigger_operator_ui_OperatorPrompt> prompts(p, protocol::operator_ui::kPrompt);
  dds::Reader<rigger_operator_ui_OperatorResponse> responses(p, protocol::operator_ui::kResponse);
  int final_state = -1;
  std::string final_code;
  std::vector<std::string> prompt_kinds;
  std::map<std::string, std::string> answers;  // prompt id → answer
  cell_.loop().on_data(statuses, [&] {
    statuses.take([&](const rigger_task_TaskStatus& s, const dds_sample_info_t&) {
      if (dds::to_string(s.task_id) != "decide") return;
      if (s.state == rigger_task_TASK_SUCCEEDED || s.state == rigger_task_TASK_FAILED ||
          s.state == rigger_task_TASK_REJECTED || s.state == rigger_task_TASK_CANCELED) {
        final_state = s.state;
        final_code = dds::to_string(s.code) + " " + dds::to_string(s.message);
      }
    });
  });
  cell_.loop().on_data(prompts, [&] {
    prompts.take([&](const rigger_operator_ui_OperatorPrompt& pr, const dds_sample_info_t&) {
      if (pr.active) prompt_kinds.push_back(dds::to_string(pr.kind));
    });
  });
  cell_.loop().on_data(responses, [&] {
    responses.take([&](const rigger_operator_ui_OperatorResponse& r, const dds_sample_info_t&) {
      answers[dds::to_string(r.prompt_id)] = dds::to_string(r.answer);
    });
  });

  cell_.start("tc", "task_controller",
              {"--id", "tc", "--config",
               write_config("tc", {{"journal_path", cell_.log_dir() + "/journal.sqlite"}, {"executor_wait_s", 0.5}})});
  cell_.start("exec", "scripted_executor",
              {"--id", "exec", "--config",
               write_config("exec", {{"skills", {"Localize"}}, {"default", {{"mode", "succeed"}, {"delay_s", 0.1}}}})});
  cell_.start(
      "operator", "scripted_operator",
      {"--id", "operator", "--config", std::string(RIGGER_SOURCE_DIR) + "/deploy/config/scripted_operator.json"});
  ASSERT_TRUE(cell_.wait_ready({"tc", "exec", "operator"}, 20s));
  ASSERT_TRUE(recipes.wait_for_readers(1, 10s));

  // Option 1 ("retry") localises the target, option 0 ("abort") the load: the answer picks the branch.
  const nlohmann::json recipe = {
      {"recipe_version", 1},
      {"task_id", "decide"},
      {"root",
       {{"type", "OperatorDecision"},
        {"prompt", "The first attempt failed. Retry?"},
        {"options",
         {{{"label", "abort"}, {"child", {{"type", "Skill"}, {"skill", "Localize"}, {"params", {{"object", "load"}}}}}},
          {{"label", "retry"},
           {"child", {{"type", "Skill"}, {"skill", "Localize"}, {"params", {{"object", "target"}}}}}}}}}}};
  const std::string text = recipe.dump(), task_id = "decide", submitter = "test";
  rigger_task_Recipe r{};
  r.task_id = dds::wire_string(task_id);
  r.recipe_json = dds::wire_string(text);
  r.submitter = dds::wire_string(submitter);
  r.stamp = dds::wire_now();
  ASSERT_EQ(recipes.write(r), DDS_RETCODE_OK);

  ASSERT_TRUE(cell_.wait_until([&] { return final_state >= 0; }, 30s));
  EXPECT_EQ(final_state, rigger_task_TASK_SUCCEEDED) << final_code;
  ASSERT_EQ(prompt_kinds, std::vector<std::string>{"decision"});
  ASSERT_EQ(answers.size(), 1u);
  EXPECT_EQ(answers.begin()->first.rfind("decide#", 0), 0u) << answers.begin()->first;
  EXPECT_EQ(answers.begin()->second, "retry");
}

}  // namespace
}  // namespace rigger::testing
