// The operator in the loop with real processes: scripted_operator answers prompts by its rules (and
// only those), riggerctl operator lists and answers prompts without a terminal, riggerctl jog publishes
// the joystick reference from a script and always ends on zero. Prompts are written and responses and
// twists read by this test's own participant on a private domain; nothing sleeps.
#include <fcntl.h>
#include <linux/joystick.h>
#include <signal.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cmath>
#include <cstring>
#include <fstream>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "rigger/dds/conversions.hpp"
#include "rigger/dds/pubsub.hpp"
#include "rigger/protocol/operator.hpp"
#include "rigger/operator_protocol/prompt.hpp"
#include "rigger/testing/cell.hpp"

namespace rigger::testing {
namespace {

using namespace std::chrono_literals;

struct SeenResponse {
  std::string answer;
  std::string operator_id;
};

struct SeenTwist {
  std::uint64_t seq = 0;
  std::array<double, 6> twist{};
  double timeout_s = 0;
  std::string frame_id;
  std::string source;
  std::int64_t stamp_ns = 0;
};

class OperatorTest : public MultiProcessTest {
 protected:
  void SetUp() override {
    auto& p = cell_.participant();
    prompts_ = std::make_unique<dds::Writer<rigger_operator_ui_OperatorPrompt>>(p, protocol::operator_ui::kPrompt);
    responses_ =
        std::make_unique<dds::Reader<rigger_operator_ui_OperatorResponse>>(p, protocol::operator_ui::kResponse);
    twists_ = std::make_unique<dds::Reader<rigger_sensing_TwistCommand>>(p, protocol::operator_ui::kJoystick);
    cell_.loop().on_data(*responses_, [this] {
      responses_->take([this](const rigger_operator_ui_OperatorResponse& r, const dds_sample_info_t&) {
        responses_seen_[dds::to_string(r.prompt_id)].push_back(
            {dds::to_string(r.answer), dds::to_string(r.operator_id)});
        response_order_.push_back(dds::to_string(r.prompt_id));
      });
    });
    cell_.loop().on_data(*twists_, [this] {
      twists_->take([this](const rigger_sensing_TwistCommand& t, const dds_sample_info_t&) {
        const auto v = dds::to_domain(t.twist);
        SeenTwist s;
        s.seq = t.seq;
        for (int i = 0; i < 6; ++i) s.twist[static_cast<std::size_t>(i)] = v[i];
        s.timeout_s = t.timeout_s;
        s.frame_id = dds::to_string(t.header.frame_id);
        s.source = dds::to_string(t.source);
        s.stamp_ns = to_unix_ns(dds::to_domain(t.header.stamp));
        twists_seen_.push_back(s);
      });
    });
  }

  void write_prompt(const std::string& id, const std::string& kind, std::vector<std::string> options,
                    const nlohmann::json& details, bool active = true) {
    operator_protocol::Prompt p;
    p.prompt_id = id;
    p.task_id = "test-task";
    p.node_id = "root/1";
    p.kind = kind;
    p.title = "Title of " + id;
    p.text = "Text of " + id;
    p.options = std::move(options);
    p.details_json = details.is_null() ? "" : details.dump();
    p.active = active;
    ASSERT_EQ(operator_protocol::write_prompt(*prompts_, p), DDS_RETCODE_OK);
  }
  void write_screw(const std::string& id, const std::string& hole, bool active = true) {
    write_prompt(id, "screw", {"done", "failed", "abort"},
                 {{"hole", hole}, {"screw_type", "M12x40"}, {"torque_nm", 60}}, active);
  }

  bool wait_for_responses(const std::vector<std::string>& ids, std::chrono::milliseconds timeout) {
    return cell_.wait_until(
        [&] {
          for (const auto& id : ids)
            if (!responses_seen_.count(id)) return false;
          return true;
        },
        timeout);
  }

  std::string write_config(const std::string& name, const nlohmann::json& config) {
    const std::string path = cell_.log_dir() + "/" + name + ".json";
    std::ofstream(path) << config.dump(2);
    return path;
  }

  /// Runs riggerctl with `args` on the test's domain to its end; returns its exit status and output.
  std::pair<ExitStatus, std::string> riggerctl(const std::string& name, std::vector<std::string> args,
                                               std::chrono::milliseconds timeout = 30s) {
    args.insert(args.begin(), {"--domain", std::to_string(cell_.domain_id())});
    auto& p = cell_.start(name, "riggerctl", args, false);
    std::optional<ExitStatus> st;
    // Keep this test's loop running meanwhile: riggerctl's answers and twists are taken as they come.
    cell_.wait_until([&] { return !p.running(); }, timeout);
    st = p.wait(1s);
    EXPECT_TRUE(st.has_value()) << name << " did not end";
    return {st.value_or(ExitStatus{}), p.log()};
  }

  std::unique_ptr<dds::Writer<rigger_operator_ui_OperatorPrompt>> prompts_;
  std::unique_ptr<dds::Reader<rigger_operator_ui_OperatorResponse>> responses_;
  std::unique_ptr<dds::Reader<rigger_sensing_TwistCommand>> twists_;
  std::map<std::string, std::vector<SeenResponse>> responses_seen_;
  std::vector<std::string> response_order_;
  std::vector<SeenTwist> twists_seen_;
};

// --- scripted_operator

TEST_F(OperatorTest, ScriptedOperatorAnswersByFirstMatchingRule) {
  const auto config = write_config(
      "operator", {{"operator_id", "test-operator"},
                   {"rules",
                    {{{"kind", "screw"}, {"match_details", {{"hole", "h2"}}}, {"answer", "failed"}, {"delay_s", 0.3}},
                     {{"kind", "screw"}, {"match_details", {{"hole", "h9"}}}, {"answer", "done"}, {"delay_s", 1.0}},
                     {{"kind", "screw"}, {"match_details", {{"hole", "h10"}}}, {"answer", "done"}, {"delay_s", 1.5}},
                     {{"kind", "screw"}, {"answer", "done"}},
                     {{"kind", "decision"}, {"answer", {"retry", "continue"}}}}}});
  // The command-line rule comes first: h3 is aborted although the file's catch-all says done.
  cell_.start("operator", "scripted_operator",
              {"--id", "operator", "--config", config, "--rule", "screw:hole=h3:abort"});
  ASSERT_TRUE(cell_.wait_ready({"operator"}, 15s));

  write_prompt("p-inspect", "inspect", {"ok", "not ok"}, nullptr);                       // no rule for this kind
  write_prompt("p-choice", "decision", {"joystick", "visual servo", "abort"}, nullptr);  // rule's answers not offered
  write_screw("p-inactive", "h1", /*active=*/false);                                     // not active: never answered
  write_screw("p-h9", "h9");                                                             // withdrawn before its 1.0 s
  write_screw("p-h1", "h1");
  write_screw("p-h2", "h2");
  write_screw("p-h3", "h3");
  write_prompt("p-decision", "decision", {"abort", "retry"}, nullptr);
  // p-h1 is answered at once; the operator has then seen every prompt before it (one writer, in order).
  ASSERT_TRUE(wait_for_responses({"p-h1"}, 15s));
  write_screw("p-h9", "h9", /*active=*/false);
  write_screw("p-h1", "h1");    // published again: still answered once
  write_screw("p-h10", "h10");  // answered after 1.5 s: by then p-h9's 1.0 s timer would have fired

  ASSERT_TRUE(wait_for_responses({"p-h1", "p-h2", "p-h3", "p-decision", "p-h10"}, 15s));
  EXPECT_EQ(responses_seen_["p-h1"].size(), 1u);
  EXPECT_EQ(responses_seen_["p-h1"].front().answer, "done");
  EXPECT_EQ(responses_seen_["p-h1"].front().operator_id, "test-operator");
  EXPECT_EQ(responses_seen_["p-h2"].front().answer, "failed");
  EXPECT_EQ(responses_seen_["p-h3"].front().answer, "abort");
  EXPECT_EQ(responses_seen_["p-decision"].front().answer, "retry");
  for (const char* left_alone : {"p-inspect", "p-choice", "p-inactive", "p-h9"})
    EXPECT_EQ(responses_seen_.count(left_alone), 0u) << left_alone << " must not be answered";
  // Delays order the answers: the undelayed ones first, h2 (0.3 s) after them, h10 (1.5 s) last.
  ASSERT_EQ(response_order_.size(), 5u);
  EXPECT_EQ(response_order_[3], "p-h2");
  EXPECT_EQ(response_order_[4], "p-h10");

  const std::string log = cell_.process("operator").log();
  EXPECT_NE(log.find("prompt screw h1 M12x40 60 N m -> done after 0.0 s"), std::string::npos) << log;
  EXPECT_NE(log.find("not answering id=p-choice"), std::string::npos) << log;
}

TEST_F(OperatorTest, ScriptedOperatorRefusesAnInvalidAnswerRuleAtStart) {
  expect_clean_exit_ = false;  // refusals exit non-zero on purpose; each one is checked here
  const auto config =
      write_config("bad-operator",
                   {{"rules", {{{"kind", "screw"}, {"answer", "done"}}, {{"kind", "screw"}, {"answer", "perhaps"}}}}});
  auto& file = cell_.start("bad-file", "scripted_operator", {"--id", "bad-file", "--config", config});
  auto st = file.wait(20s);
  ASSERT_TRUE(st.has_value());
  EXPECT_TRUE(st->exited);
  EXPECT_EQ(st->code, 2);
  EXPECT_NE(file.log().find(config), std::string::npos) << file.log();
  EXPECT_NE(file.log().find("/rules/1/answer"), std::string::npos) << file.log();
  EXPECT_NE(file.log().find("done, failed, abort"), std::string::npos) << file.log();

  auto& cli = cell_.start("bad-cli", "scripted_operator", {"--id", "bad-cli", "--rule", "screw:hole=h1:maybe"});
  st = cli.wait(20s);
  ASSERT_TRUE(st.has_value());
  EXPECT_EQ(st->code, 2);
  EXPECT_NE(cli.log().find("--rule 'screw:hole=h1:maybe' at /answer"), std::string::npos) << cli.log();
}

// --- riggerctl operator

TEST_F(OperatorTest, RiggerctlOperatorListsAndAnswers) {
  expect_clean_exit_ = false;  // refusals exit non-zero on purpose; each one is checked here
  write_screw("p1", "h1");
  write_prompt("p2", "decision", {"joystick", "visual servo", "abort"}, nullptr);
  write_screw("p3", "h3");
  write_screw("p3", "h3", /*active=*/false);  // withdrawn: not listed, cannot be answered

  auto [list_status, list] = riggerctl("list", {"operator", "--list", "--timeout", "3"});
  EXPECT_TRUE(list_status.ok()) << list;
  EXPECT_NE(list.find(": p1"), std::string::npos) << list;
  EXPECT_NE(list.find("screw_type: M12x40"), std::string::npos) << list;
  EXPECT_NE(list.find("torque_nm: 60 N m"), std::string::npos) << list;
  EXPECT_NE(list.find("[1] done"), std::string::npos) << list;
  EXPECT_NE(list.find(": p2"), std::string::npos) << list;
  EXPECT_NE(list.find("[2] visual servo"), std::string::npos) << list;
  EXPECT_EQ(list.find(": p3"), std::string::npos) << list;

  // By number, with an operator id.
  auto [by_number, out1] = riggerctl("answer-number", {"operator", "--answer", "p2=2", "--operator-id", "tester"});
  EXPECT_TRUE(by_number.ok()) << out1;
  ASSERT_TRUE(wait_for_responses({"p2"}, 10s));
  EXPECT_EQ(responses_seen_["p2"].front().answer, "visual servo");
  EXPECT_EQ(responses_seen_["p2"].front().operator_id, "tester");

  // Not an option: refused, nothing written.
  auto [wrong, out2] = riggerctl("answer-wrong", {"operator", "--answer", "p1=maybe"});
  EXPECT_TRUE(wrong.exited);
  EXPECT_EQ(wrong.code, 1) << out2;
  EXPECT_NE(out2.find("not an option of prompt 'p1'"), std::string::npos) << out2;

  // Withdrawn: refused.
  auto [withdrawn, out3] = riggerctl("answer-withdrawn", {"operator", "--answer", "p3=done", "--timeout", "5"});
  EXPECT_EQ(withdrawn.code, 1) << out3;
  EXPECT_NE(out3.find("withdrawn"), std::string::npos) << out3;

  // Malformed: usage.
  auto [usage, out4] = riggerctl("answer-usage", {"operator", "--answer", "p1"});
  EXPECT_EQ(usage.code, 2) << out4;

  // By text.
  auto [by_text, out5] = riggerctl("answer-text", {"operator", "--answer", "p1=done"});
  EXPECT_TRUE(by_text.ok()) << out5;
  ASSERT_TRUE(wait_for_responses({"p1"}, 10s));
  ASSERT_EQ(responses_seen_["p1"].size(), 1u);  // the refused "maybe" never went out
  EXPECT_EQ(responses_seen_["p1"].front().answer, "done");
  EXPECT_EQ(responses_seen_.count("p3"), 0u);
}

// --- riggerctl jog

TEST_F(OperatorTest, RiggerctlJogScriptPublishesTheStepsThenZero) {
  auto [st, out] = riggerctl("jog", {"jog", "--script", "x+0.05:0.6s,y-0.03:0.4s", "--rate", "50", "--timeout", "0.3"});
  EXPECT_TRUE(st.ok()) << out;
  EXPECT_NE(out.find("the last one zero"), std::string::npos) << out;
  // jog waits for its readers' acknowledgement before it exits: the final zero is here or on its way.
  ASSERT_TRUE(cell_.wait_until(
      [&] { return !twists_seen_.empty() && twists_seen_.back().twist == std::array<double, 6>{}; }, 5s));
  ASSERT_GE(twists_seen_.size(), 5u);
  const std::array<double, 6> x{0.05, 0, 0, 0, 0, 0}, y{0, -0.03, 0, 0, 0, 0}, zero{};
  std::vector<std::array<double, 6>> phases;
  for (std::size_t i = 0; i < twists_seen_.size(); ++i) {
    const auto& s = twists_seen_[i];
    if (i > 0) {
      EXPECT_GT(s.seq, twists_seen_[i - 1].seq) << "sample " << i;
    }
    EXPECT_DOUBLE_EQ(s.timeout_s, 0.3);
    EXPECT_EQ(s.frame_id, "base");
    EXPECT_EQ(s.source.rfind("riggerctl-jog", 0), 0u) << s.source;
    EXPECT_GT(s.stamp_ns, 0);
    if (phases.empty() || phases.back() != s.twist) phases.push_back(s.twist);
  }
  EXPECT_EQ(phases, (std::vector<std::array<double, 6>>{x, y, zero}));
}

TEST_F(OperatorTest, RiggerctlJogEndsOnZeroWhenInterrupted) {
  auto& jog = cell_.start("jog", "riggerctl",
                          {"--domain", std::to_string(cell_.domain_id()), "jog", "--script", "z+0.02:60s"}, false);
  ASSERT_TRUE(cell_.wait_until([&] { return !twists_seen_.empty(); }, 15s)) << jog.log();
  EXPECT_DOUBLE_EQ(twists_seen_.front().twist[2], 0.02);
  ASSERT_TRUE(jog.signal(SIGINT));
  ASSERT_TRUE(cell_.wait_until([&] { return !jog.running(); }, 10s));
  const auto st = jog.wait(1s);
  ASSERT_TRUE(st.has_value());
  EXPECT_TRUE(st->ok()) << jog.log();
  ASSERT_TRUE(cell_.wait_until([&] { return twists_seen_.back().twist == std::array<double, 6>{}; }, 5s))
      << "the last twist after SIGINT must be zero";
}

TEST_F(OperatorTest, RiggerctlJogFollowsAJoystickDeviceAndStopsWhenItIsLost) {
  expect_clean_exit_ = false;  // a lost device ends jog with exit code 1 on purpose
  // A FIFO stands in for /dev/input/js0: jog reads linux/joystick.h events from it the same way.
  const std::string device = cell_.log_dir() + "/js0";
  ASSERT_EQ(mkfifo(device.c_str(), 0600), 0) << std::strerror(errno);
  auto& jog =
      cell_.start("jog", "riggerctl",
                  {"--domain", std::to_string(cell_.domain_id()), "jog", "--device", device, "--speed", "0.1"}, false);
  const int fd = open(device.c_str(), O_WRONLY);  // returns once jog opened its end
  ASSERT_GE(fd, 0) << std::strerror(errno);
  // Left stick fully forward (axis 1 at -32767): +x at the full speed.
  const js_event forward{0, -32767, JS_EVENT_AXIS, 1};
  ASSERT_EQ(write(fd, &forward, sizeof forward), static_cast<ssize_t>(sizeof forward));
  const bool moved = cell_.wait_until(
      [&] { return !twists_seen_.empty() && std::abs(twists_seen_.back().twist[0] - 0.1) < 1e-9; }, 15s);
  close(fd);  // the device is gone
  ASSERT_TRUE(moved) << jog.log();
  ASSERT_TRUE(cell_.wait_until([&] { return !jog.running(); }, 10s));
  const auto st = jog.wait(1s);
  ASSERT_TRUE(st.has_value());
  EXPECT_EQ(st->code, 1) << jog.log();
  EXPECT_NE(jog.log().find("end of input"), std::string::npos) << jog.log();
  ASSERT_TRUE(cell_.wait_until([&] { return twists_seen_.back().twist == std::array<double, 6>{}; }, 5s))
      << "the last twist after losing the device must be zero";
}

TEST_F(OperatorTest, RiggerctlJogRefusesABadScript) {
  expect_clean_exit_ = false;  // refusals exit non-zero on purpose; each one is checked here
  auto [st, out] = riggerctl("jog-bad", {"jog", "--script", "x+0.5:1s"});
  EXPECT_EQ(st.code, 2) << out;
  EXPECT_NE(out.find("above the limit"), std::string::npos) << out;
  EXPECT_TRUE(twists_seen_.empty());
}

}  // namespace
}  // namespace rigger::testing
