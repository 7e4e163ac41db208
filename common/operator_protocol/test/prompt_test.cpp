// Prompts and answers through rigger/operator/{prompt,response} and back, on a private domain.

#include "rigger/operator_protocol/prompt.hpp"

#include <gtest/gtest.h>

#include <chrono>
#include <optional>

#include "rigger/dds/event_loop.hpp"
#include "rigger/testing/domain.hpp"

namespace rigger::operator_protocol {
namespace {

using namespace std::chrono_literals;

class OperatorProtocolTest : public ::testing::Test {
 protected:
  rigger::testing::DomainLease domain_;
  dds::Participant participant_{domain_.id()};
  dds::EventLoop loop_{participant_};
};

TEST_F(OperatorProtocolTest, APromptAndItsAnswerSurviveTheWire) {
  dds::Writer<rigger_operator_ui_OperatorPrompt> prompts(participant_, protocol::operator_ui::kPrompt);
  dds::Reader<rigger_operator_ui_OperatorPrompt> prompt_reader(participant_, protocol::operator_ui::kPrompt);
  dds::Writer<rigger_operator_ui_OperatorResponse> responses(participant_, protocol::operator_ui::kResponse);
  dds::Reader<rigger_operator_ui_OperatorResponse> response_reader(participant_, protocol::operator_ui::kResponse);
  ASSERT_TRUE(prompts.wait_for_readers(1, 5s));
  ASSERT_TRUE(responses.wait_for_readers(1, 5s));

  const Prompt sent{"t#n#1",         "t",           "n",         "confirm", "Check the load",
                    "Is it hooked?", {"yes", "no"}, "{\"a\":1}", 12.5,      true};
  ASSERT_EQ(write_prompt(prompts, sent), DDS_RETCODE_OK);
  ASSERT_EQ(write_response(responses, sent.prompt_id, "yes", "alice", "looks fine"), DDS_RETCODE_OK);

  std::optional<Prompt> prompt;
  std::optional<Response> response;
  loop_.on_data(prompt_reader, [&] {
    prompt_reader.take(
        [&](const rigger_operator_ui_OperatorPrompt& w, const dds_sample_info_t&) { prompt = from_wire(w); });
  });
  loop_.on_data(response_reader, [&] {
    response_reader.take(
        [&](const rigger_operator_ui_OperatorResponse& w, const dds_sample_info_t&) { response = from_wire(w); });
  });
  ASSERT_TRUE(loop_.run_until([&] { return prompt && response; }, 5s));

  ASSERT_TRUE(prompt);
  EXPECT_EQ(prompt->prompt_id, sent.prompt_id);
  EXPECT_EQ(prompt->task_id, sent.task_id);
  EXPECT_EQ(prompt->node_id, sent.node_id);
  EXPECT_EQ(prompt->kind, sent.kind);
  EXPECT_EQ(prompt->title, sent.title);
  EXPECT_EQ(prompt->text, sent.text);
  EXPECT_EQ(prompt->options, sent.options);
  EXPECT_EQ(prompt->details_json, sent.details_json);
  EXPECT_DOUBLE_EQ(prompt->timeout_s, sent.timeout_s);
  EXPECT_TRUE(prompt->active);
  ASSERT_TRUE(response);
  EXPECT_EQ(response->prompt_id, sent.prompt_id);
  EXPECT_EQ(response->answer, "yes");
  EXPECT_EQ(response->operator_id, "alice");
  EXPECT_EQ(response->comment, "looks fine");
}

}  // namespace
}  // namespace rigger::operator_protocol
