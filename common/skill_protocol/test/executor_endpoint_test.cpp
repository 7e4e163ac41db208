// The executor side of the protocol, driven by a raw controller-side writer/reader in the same process.
#include "rigger/skill_protocol/executor_endpoint.hpp"

#include <gtest/gtest.h>

#include "rigger/dds/conversions.hpp"
#include "rigger/protocol/skill.hpp"
#include "rigger/testing/domain.hpp"

namespace rigger::skill_protocol {
namespace {

using namespace std::chrono_literals;

struct Event {
  std::string node, kind_code, message;
  rigger_skill_SkillEventKind kind;
  std::uint64_t seq, command_seq;
};

class ExecutorEndpointTest : public ::testing::Test {
 protected:
  ExecutorEndpointTest() {
    library_ = {
        {"library_version", 1},
        {"skills",
         {{{"name", "Wait"}},
          {{"name", "Grasp"}},
          {{"name", "MoveArm"}, {"kind", "skill"}, {"params", nlohmann::json::array()}, {"resources", {"robot"}}},
          {{"name", "Weld"}, {"kind", "skill"}, {"params", nlohmann::json::array()}, {"resources", {"robot"}}},
          {{"name", "Look"}, {"kind", "skill"}, {"params", nlohmann::json::array()}, {"resources", {"camera"}}},
          {{"name", "Hoist"},
           {"kind", "skill"},
           {"params", nlohmann::json::array()},
           {"resources", {"crane"}},
           {"pausable", true}},
          {{"name", "Watch"}, {"kind", "monitor"}, {"params", nlohmann::json::array()}}}}};
    ExecutorEndpoint::Options options;
    options.start_wait = 300ms;
    endpoint_ = std::make_unique<ExecutorEndpoint>(
        participant_, loop_, null_logger(), "exec-1", library_,
        ExecutorEndpoint::Handlers{[this](const StartRequest& r) { starts_.push_back(r); },
                                   [this](const ShutdownRequest& r) {
                                     shutdowns_.push_back(r);
                                     // A skill with nothing to stop ends inside the shutdown call.
                                     if (stop_at_once_) endpoint_->report(r.run, EventKind::kStopped);
                                   },
                                   [this](const PauseRequest& r) {
                                     pauses_.push_back(r);
                                     return PauseAnswer{"", r.pause ? "holds" : "continues"};
                                   }},
        options);
    loop_.on_data(events_, [this] {
      events_.take([this](const rigger_skill_SkillEvent& e, const dds_sample_info_t&) {
        // The answers to STARTs apart, so that the skills' own events keep their indices.
        auto& into = e.kind == rigger_skill_SKILL_EVENT_ACCEPTED ? accepted_ : received_;
        into.push_back({dds::to_string(e.node_id), dds::to_string(e.code), dds::to_string(e.message), e.kind, e.seq,
                        e.command_seq});
      });
    });
    EXPECT_TRUE(commands_.wait_for_readers(1, 5s));
  }

  void send(const std::string& executor, const std::string& node, rigger_skill_SkillCommandKind kind, std::uint64_t seq,
            const std::string& skill = "Wait", const std::string& params = "{}") {
    send_with(commands_, executor, node, kind, seq, skill, params);
  }
  void send_with(const dds::Writer<rigger_skill_SkillCommand>& writer, const std::string& executor,
                 const std::string& node, rigger_skill_SkillCommandKind kind, std::uint64_t seq,
                 const std::string& skill = "Wait", const std::string& params = "{}") {
    rigger_skill_SkillCommand c{};
    const std::string task = "t1", reason = "test";
    c.executor_id = dds::wire_string(executor);
    c.task_id = dds::wire_string(task);
    c.node_id = dds::wire_string(node);
    c.skill = dds::wire_string(skill);
    c.kind = kind;
    c.params_json = dds::wire_string(params);
    c.reason = dds::wire_string(reason);
    c.seq = seq;
    ASSERT_EQ(writer.write(c), DDS_RETCODE_OK);
  }

  testing::DomainLease domain_;
  dds::Participant participant_{domain_.id()};
  dds::EventLoop loop_{participant_};
  dds::Writer<rigger_skill_SkillCommand> commands_{participant_, protocol::skill::kCommand};
  dds::Reader<rigger_skill_SkillEvent> events_{participant_, protocol::skill::kEvent};
  nlohmann::json library_;
  std::unique_ptr<ExecutorEndpoint> endpoint_;
  std::vector<StartRequest> starts_;
  std::vector<ShutdownRequest> shutdowns_;
  std::vector<PauseRequest> pauses_;
  bool stop_at_once_ = false;
  std::vector<Event> received_;
  std::vector<Event> accepted_;  ///< ACCEPTED events
};

TEST_F(ExecutorEndpointTest, StartThenSuccessCarriesTheStartSeq) {
  send("exec-1", "n1", rigger_skill_SKILL_START, 7, "Wait", R"({"duration_s": 2})");
  ASSERT_TRUE(loop_.run_until([&] { return starts_.size() == 1; }, 5s));
  EXPECT_EQ(starts_[0].skill, "Wait");
  EXPECT_EQ(starts_[0].params["duration_s"], 2);
  EXPECT_EQ(starts_[0].run.start_seq, 7u);
  EXPECT_TRUE(endpoint_->report(starts_[0].run, EventKind::kProgress, "", "half", 0.5));
  EXPECT_TRUE(endpoint_->report(starts_[0].run, EventKind::kSuccess));
  ASSERT_TRUE(loop_.run_until([&] { return received_.size() == 2; }, 5s));
  EXPECT_EQ(received_[0].kind, rigger_skill_SKILL_EVENT_PROGRESS);
  EXPECT_EQ(received_[1].kind, rigger_skill_SKILL_EVENT_SUCCESS);
  EXPECT_EQ(received_[1].command_seq, 7u);
  EXPECT_LT(received_[0].seq, received_[1].seq);
  // The endpoint answered the START itself, before the skill's first event.
  ASSERT_EQ(accepted_.size(), 1u);
  EXPECT_EQ(accepted_[0].command_seq, 7u);
  EXPECT_EQ(accepted_[0].kind_code, "");
  EXPECT_LT(accepted_[0].seq, received_[0].seq);
  // A skill cannot send the endpoint's answer.
  EXPECT_FALSE(endpoint_->report(starts_[0].run, EventKind::kAccepted));
  // The run is over: a late report is dropped, not sent.
  EXPECT_FALSE(endpoint_->report(starts_[0].run, EventKind::kFailure, "LATE"));
  EXPECT_TRUE(endpoint_->active_runs().empty());
}

TEST_F(ExecutorEndpointTest, IgnoresOtherExecutorsAndDuplicateSeqs) {
  send("exec-2", "n1", rigger_skill_SKILL_START, 1);
  send("exec-1", "n2", rigger_skill_SKILL_START, 5);
  send("exec-1", "n3", rigger_skill_SKILL_START, 5);  // duplicate seq: dropped
  send("exec-1", "n4", rigger_skill_SKILL_START, 4);  // older, never seen: a START sent again, taken
  send("exec-1", "n4", rigger_skill_SKILL_START, 4);  // and only once
  send("exec-1", "n5", rigger_skill_SKILL_START, 6);
  ASSERT_TRUE(loop_.run_until([&] { return starts_.size() == 3; }, 5s));
  loop_.run_until([] { return false; }, 100ms);  // nothing else may arrive
  ASSERT_EQ(starts_.size(), 3u);
  EXPECT_EQ(starts_[0].run.node_id, "n2");
  EXPECT_EQ(starts_[1].run.node_id, "n4");
  EXPECT_EQ(starts_[2].run.node_id, "n5");
}

TEST(CommandOrder, TakesEachSeqOnceAndDropsWhatIsOlderThanTheWindow) {
  CommandOrder order;
  std::uint64_t last = 99;
  EXPECT_FALSE(order.accept(0, &last)) << "seq 0 is never a command's";
  EXPECT_EQ(last, 0u);
  EXPECT_TRUE(order.accept(10, &last));
  EXPECT_TRUE(order.accept(12, &last));
  EXPECT_EQ(last, 10u);
  EXPECT_FALSE(order.accept(12));
  EXPECT_TRUE(order.accept(11, &last)) << "a command sent again after a newer one";
  EXPECT_EQ(last, 12u);
  EXPECT_FALSE(order.accept(11));
  EXPECT_TRUE(order.accept(3)) << "the window is not full: nothing taken is forgotten yet";
  // Fill the window: the oldest seqs are forgotten, and anything older than the window is stale.
  for (std::uint64_t s = 100; s < 100 + CommandOrder::kWindow; ++s) ASSERT_TRUE(order.accept(s));
  EXPECT_FALSE(order.accept(99)) << "older than every seq remembered";
  EXPECT_FALSE(order.accept(100)) << "seen";
  EXPECT_TRUE(order.accept(100 + CommandOrder::kWindow + 5));
  EXPECT_FALSE(order.accept(100)) << "now older than the window";
  EXPECT_TRUE(order.accept(100 + CommandOrder::kWindow + 1)) << "inside the window, not seen";
}

TEST_F(ExecutorEndpointTest, BadParamsAndUnknownSkillFailWithCodes) {
  send("exec-1", "bad", rigger_skill_SKILL_START, 1, "Wait", "{not json");
  send("exec-1", "arr", rigger_skill_SKILL_START, 2, "Wait", "[1,2]");
  send("exec-1", "unk", rigger_skill_SKILL_START, 3, "Fly", "{}");
  ASSERT_TRUE(loop_.run_until([&] { return received_.size() == 3; }, 5s));
  EXPECT_TRUE(starts_.empty());
  EXPECT_EQ(received_[0].kind_code, "BAD_PARAMS");
  EXPECT_NE(received_[0].message.find("params of Wait unreadable: 1:3:"), std::string::npos) << received_[0].message;
  EXPECT_EQ(received_[1].kind_code, "BAD_PARAMS");
  EXPECT_NE(received_[1].message.find("must be a JSON object, got array"), std::string::npos) << received_[1].message;
  EXPECT_EQ(received_[2].kind_code, "UNKNOWN_SKILL");
  for (const auto& e : received_) EXPECT_EQ(e.kind, rigger_skill_SKILL_EVENT_FAILURE);
}

// Parameters from another process are bounded while parsed: too deep or too large is refused, with where.
TEST_F(ExecutorEndpointTest, ParamsTooDeepOrTooLargeAreRefusedWhileParsed) {
  send("exec-1", "deep", rigger_skill_SKILL_START, 1, "Wait", "{\"a\":" + std::string(100000, '[') + "}");
  send("exec-1", "big", rigger_skill_SKILL_START, 2, "Wait", "{\"s\":\"" + std::string(300 * 1024, 'x') + "\"}");
  send("exec-1", "dup", rigger_skill_SKILL_START, 3, "Wait", "{\"t\":1,\"t\":2}");
  ASSERT_TRUE(loop_.run_until([&] { return received_.size() == 3; }, 5s));
  EXPECT_TRUE(starts_.empty());
  for (const auto& e : received_) EXPECT_EQ(e.kind_code, "BAD_PARAMS") << e.node;
  EXPECT_NE(received_[0].message.find("deeper than 32 levels"), std::string::npos) << received_[0].message;
  EXPECT_NE(received_[1].message.find("262144"), std::string::npos) << received_[1].message;
  EXPECT_NE(received_[2].message.find("duplicate key \"t\""), std::string::npos) << received_[2].message;
}

TEST_F(ExecutorEndpointTest, ShutdownOfARunningLeafReachesTheHandler) {
  send("exec-1", "n1", rigger_skill_SKILL_START, 1);
  send("exec-1", "n1", rigger_skill_SKILL_SHUTDOWN, 2);
  ASSERT_TRUE(loop_.run_until([&] { return shutdowns_.size() == 1; }, 5s));
  EXPECT_EQ(shutdowns_[0].run.start_seq, 1u);
  EXPECT_EQ(shutdowns_[0].reason, "test");
  EXPECT_TRUE(endpoint_->report(shutdowns_[0].run, EventKind::kStopped));
  ASSERT_TRUE(loop_.run_until([&] { return received_.size() == 1; }, 5s));
  EXPECT_EQ(received_[0].kind, rigger_skill_SKILL_EVENT_STOPPED);
}

TEST_F(ExecutorEndpointTest, ShutdownOfAnUnknownLeafIsAcknowledgedAtOnce) {
  send("exec-1", "ghost", rigger_skill_SKILL_SHUTDOWN, 1);
  ASSERT_TRUE(loop_.run_until([&] { return received_.size() == 1; }, 5s));
  EXPECT_TRUE(shutdowns_.empty());
  EXPECT_EQ(received_[0].kind, rigger_skill_SKILL_EVENT_STOPPED);
  EXPECT_EQ(received_[0].kind_code, "NOT_RUNNING");
}

TEST_F(ExecutorEndpointTest, AnnouncesItsLibrary) {
  dds::Reader<rigger_skill_ExecutorAnnouncement> reader(participant_, protocol::skill::kExecutors, dds::qos::state());
  std::string library;
  std::vector<std::string> skills;
  loop_.on_data(reader, [&] {
    reader.take([&](const rigger_skill_ExecutorAnnouncement& a, const dds_sample_info_t&) {
      library = dds::to_string(a.library_json);
      skills = dds::to_string_vector(a.skills);
    });
  });
  ASSERT_TRUE(loop_.run_until([&] { return !library.empty(); }, 5s));
  EXPECT_EQ(nlohmann::json::parse(library), library_);
  EXPECT_EQ(skills, (std::vector<std::string>{"Wait", "Grasp", "MoveArm", "Weld", "Look", "Hoist", "Watch"}));
}

// The runs held here are announced (a restarted controller learns from them what is still running or
// stopping), again at once whenever they change, and each announcement written after the event that
// changed them.
TEST_F(ExecutorEndpointTest, AnnouncesTheRunsItHoldsAtOnceWhenTheyChange) {
  dds::Reader<rigger_skill_ExecutorAnnouncement> reader(participant_, protocol::skill::kExecutors, dds::qos::state());
  std::vector<std::vector<AnnouncedRun>> seen;
  loop_.on_data(reader, [&] {
    reader.take(
        [&](const rigger_skill_ExecutorAnnouncement& a, const dds_sample_info_t&) { seen.push_back(runs_of(a)); });
  });
  ASSERT_TRUE(loop_.run_until([&] { return !seen.empty(); }, 5s));
  EXPECT_TRUE(seen.back().empty());
  const AnnouncedRun move{"t1", "move", "MoveArm", {"robot"}, false};
  const AnnouncedRun look{"t1", "look", "Look", {"camera"}, false};
  AnnouncedRun move_stopping = move;
  move_stopping.stopping = true;
  // Long before the once-a-second re-announcement: each change is announced by itself.
  const auto changed = [&](const std::vector<AnnouncedRun>& runs) {
    return loop_.run_until([&] { return !seen.empty() && seen.back() == runs; }, 500ms);
  };
  send("exec-1", "move", rigger_skill_SKILL_START, 1, "MoveArm");
  ASSERT_TRUE(changed({move}));
  send("exec-1", "look", rigger_skill_SKILL_START, 2, "Look");
  ASSERT_TRUE(changed({look, move}));
  send("exec-1", "move", rigger_skill_SKILL_SHUTDOWN, 3);
  ASSERT_TRUE(changed({look, move_stopping}));
  EXPECT_EQ(endpoint_->announced_runs(), (std::vector<AnnouncedRun>{look, move_stopping}));
  ASSERT_EQ(shutdowns_.size(), 1u);
  EXPECT_TRUE(endpoint_->report(shutdowns_[0].run, EventKind::kStopped));
  ASSERT_TRUE(changed({look}));
  // The STOPPED was written before the announcement without its run (one participant: in order).
  ASSERT_TRUE(loop_.run_until([&] { return received_.size() == 1; }, 5s));
  EXPECT_EQ(received_[0].kind, rigger_skill_SKILL_EVENT_STOPPED);
  EXPECT_TRUE(endpoint_->report(starts_[1].run, EventKind::kSuccess));
  ASSERT_TRUE(changed({}));
}

TEST(ExecutorRunWire, RoundTrips) {
  const std::vector<AnnouncedRun> runs = {{"t1", "root/0", "MoveArm", {"robot", "gripper"}, true},
                                          {"t2", "root", "Look", {}, false}};
  rigger_skill_ExecutorAnnouncement a{};
  WireRuns storage;
  wire_runs(a, runs, storage);
  EXPECT_EQ(runs_of(a), runs);
  rigger_skill_ExecutorAnnouncement none{};
  EXPECT_TRUE(runs_of(none).empty());
}

TEST_F(ExecutorEndpointTest, StartOnAResourceARunningSkillHoldsIsRefusedNamingTheHolder) {
  send("exec-1", "move", rigger_skill_SKILL_START, 1, "MoveArm");
  send("exec-1", "weld", rigger_skill_SKILL_START, 2, "Weld");
  send("exec-1", "look", rigger_skill_SKILL_START, 3, "Look");  // another resource: runs alongside
  ASSERT_TRUE(loop_.run_until([&] { return received_.size() == 1 && starts_.size() == 2; }, 5s));
  EXPECT_EQ(starts_[0].run.node_id, "move");
  EXPECT_EQ(starts_[1].run.node_id, "look");
  EXPECT_EQ(received_[0].node, "weld");
  EXPECT_EQ(received_[0].kind, rigger_skill_SKILL_EVENT_FAILURE);
  EXPECT_EQ(received_[0].kind_code, "RESOURCE_BUSY");
  EXPECT_EQ(received_[0].command_seq, 2u);
  EXPECT_NE(received_[0].message.find("resource 'robot', held by MoveArm (task t1, node move)"), std::string::npos)
      << received_[0].message;
  // The refused START never ran: the holder's run is untouched and ends normally.
  EXPECT_TRUE(endpoint_->report(starts_[0].run, EventKind::kSuccess));
}

TEST_F(ExecutorEndpointTest, StartOfANodeThatRunsAndWasNotStoppedFailsAlreadyRunning) {
  send("exec-1", "move", rigger_skill_SKILL_START, 1, "MoveArm");
  send("exec-1", "move", rigger_skill_SKILL_START, 2, "MoveArm");
  ASSERT_TRUE(loop_.run_until([&] { return received_.size() == 1; }, 5s));
  EXPECT_EQ(starts_.size(), 1u);
  EXPECT_EQ(received_[0].kind_code, "ALREADY_RUNNING");
  EXPECT_EQ(received_[0].command_seq, 2u);
}

// Retry after an escalated stop: the executor is still stopping the first run when the second START
// comes. The START waits and runs once the stop completes; it is never dropped.
TEST_F(ExecutorEndpointTest, StartWaitsForTheStopOfThePreviousRunThenRuns) {
  send("exec-1", "move", rigger_skill_SKILL_START, 1, "MoveArm");
  send("exec-1", "move", rigger_skill_SKILL_SHUTDOWN, 2, "MoveArm");
  ASSERT_TRUE(loop_.run_until([&] { return shutdowns_.size() == 1; }, 5s));
  send("exec-1", "move", rigger_skill_SKILL_START, 3, "MoveArm");
  send("exec-1", "weld", rigger_skill_SKILL_START, 4, "Weld");  // same resource, also waits
  loop_.run_until([] { return false; }, 100ms);
  ASSERT_EQ(starts_.size(), 1u) << "a START ran while the previous run still held the robot";
  EXPECT_TRUE(received_.empty());
  EXPECT_TRUE(endpoint_->report(shutdowns_[0].run, EventKind::kStopped));
  ASSERT_TRUE(loop_.run_until([&] { return starts_.size() == 2; }, 5s));
  EXPECT_EQ(starts_[1].run.node_id, "move");
  EXPECT_EQ(starts_[1].run.start_seq, 3u);
  // The second run holds the robot now and was not asked to stop: Weld is refused, naming it.
  ASSERT_TRUE(loop_.run_until([&] { return received_.size() == 2; }, 5s));
  EXPECT_EQ(received_[1].node, "weld");
  EXPECT_EQ(received_[1].kind_code, "RESOURCE_BUSY");
  // Each waiting START was answered at once (WAITING, naming what it waits for), and the one that ran
  // again when it ran, before weld's refusal (one writer: in order).
  std::vector<std::string> answers;
  for (const auto& a : accepted_) answers.push_back(a.node + "#" + std::to_string(a.command_seq) + ":" + a.kind_code);
  EXPECT_EQ(answers, (std::vector<std::string>{"move#1:", "move#3:WAITING", "weld#4:WAITING", "move#3:"}));
  EXPECT_NE(accepted_.at(1).message.find("its previous run still stopping"), std::string::npos)
      << accepted_.at(1).message;
}

TEST_F(ExecutorEndpointTest, AWaitingStartFailsWhenTheStopNeverCompletes) {
  send("exec-1", "move", rigger_skill_SKILL_START, 1, "MoveArm");
  send("exec-1", "move", rigger_skill_SKILL_SHUTDOWN, 2, "MoveArm");
  send("exec-1", "move", rigger_skill_SKILL_START, 3, "MoveArm");
  ASSERT_TRUE(loop_.run_until([&] { return received_.size() == 1; }, 5s));
  EXPECT_EQ(starts_.size(), 1u);
  EXPECT_EQ(received_[0].kind, rigger_skill_SKILL_EVENT_FAILURE);
  EXPECT_EQ(received_[0].kind_code, "STILL_STOPPING");
  EXPECT_EQ(received_[0].command_seq, 3u);
  EXPECT_NE(received_[0].message.find("its previous run still stopping"), std::string::npos) << received_[0].message;
}

TEST_F(ExecutorEndpointTest, AShutdownOfAWaitingStartStopsItBeforeItRuns) {
  send("exec-1", "move", rigger_skill_SKILL_START, 1, "MoveArm");
  send("exec-1", "move", rigger_skill_SKILL_SHUTDOWN, 2, "MoveArm");
  send("exec-1", "move", rigger_skill_SKILL_START, 3, "MoveArm");
  send("exec-1", "move", rigger_skill_SKILL_SHUTDOWN, 4, "MoveArm");
  ASSERT_TRUE(loop_.run_until([&] { return received_.size() == 1; }, 5s));
  EXPECT_EQ(received_[0].kind, rigger_skill_SKILL_EVENT_STOPPED);
  EXPECT_EQ(received_[0].kind_code, "NOT_STARTED");
  EXPECT_EQ(received_[0].command_seq, 3u);
  EXPECT_TRUE(endpoint_->report(shutdowns_.at(0).run, EventKind::kStopped));
  loop_.run_until([] { return false; }, 100ms);
  EXPECT_EQ(starts_.size(), 1u);
}

// A controller that stops asserting its liveliness (killed or hung) loses its runs: each is shut down.
TEST_F(ExecutorEndpointTest, RunsOfALostControllerAreShutDown) {
  dds::Qos leased = dds::qos::commands();
  leased.manual_liveliness(200ms);
  dds::Participant controller(domain_.id());
  dds::Writer<rigger_skill_SkillCommand> controller_commands(controller, protocol::skill::kCommand, leased);
  ASSERT_TRUE(controller_commands.wait_for_readers(1, 5s));
  send("exec-1", "look", rigger_skill_SKILL_START, 1, "Look");  // the test's own (unleased) writer
  send_with(controller_commands, "exec-1", "move", rigger_skill_SKILL_START, 1, "MoveArm");
  ASSERT_TRUE(loop_.run_until([&] { return starts_.size() == 2; }, 5s));
  // Nobody asserts the controller's liveliness: its lease runs out 200 ms after its last write.
  ASSERT_TRUE(loop_.run_until([&] { return !shutdowns_.empty(); }, 5s));
  loop_.run_until([] { return false; }, 100ms);
  ASSERT_EQ(shutdowns_.size(), 1u) << "only the lost controller's run is shut down";
  EXPECT_EQ(shutdowns_[0].run.node_id, "move");
  EXPECT_NE(shutdowns_[0].reason.find("CONTROLLER_LOST"), std::string::npos);
}

// A controller's writers share its liveliness: when one of them lapses, the runs any of them started are
// shut down, without waiting for each writer's own lapse to be reported. Here the writer that starts the
// run has a 30 s lease and its sibling 200 ms: nobody asserts, and the run must end with the sibling.
TEST_F(ExecutorEndpointTest, RunsStartedByAnyWriterOfALostControllerAreShutDown) {
  dds::Participant controller(domain_.id());
  dds::Qos long_lease = dds::qos::commands();
  long_lease.manual_liveliness(30s);
  dds::Writer<rigger_skill_SkillCommand> route(controller, protocol::skill::kCommand, long_lease);
  ASSERT_TRUE(route.wait_for_readers(1, 5s));
  send_with(route, "exec-1", "move", rigger_skill_SKILL_START, 1, "MoveArm");
  ASSERT_TRUE(loop_.run_until([&] { return starts_.size() == 1; }, 5s));
  dds::Qos short_lease = dds::qos::commands();
  short_lease.manual_liveliness(200ms);
  dds::Writer<rigger_skill_SkillCommand> sibling(controller, protocol::skill::kCommand, short_lease);
  ASSERT_TRUE(sibling.wait_for_readers(1, 5s));
  controller.assert_liveliness();  // both writers alive now; then nobody asserts again
  ASSERT_TRUE(loop_.run_until([&] { return !shutdowns_.empty(); }, 5s))
      << "the run waited for its own writer's 30 s lease";
  EXPECT_EQ(shutdowns_[0].run.node_id, "move");
  EXPECT_NE(shutdowns_[0].reason.find("CONTROLLER_LOST"), std::string::npos);
}

// Skills that stop at once, inside the shutdown call, end their runs while the lost controller's runs are
// still being shut down (this crashed an executor once: the loop walked the runs it was erasing).
TEST_F(ExecutorEndpointTest, RunsThatStopAtOnceWhenTheirControllerIsLostEndCleanly) {
  stop_at_once_ = true;
  dds::Qos leased = dds::qos::commands();
  leased.manual_liveliness(200ms);
  dds::Participant controller(domain_.id());
  dds::Writer<rigger_skill_SkillCommand> controller_commands(controller, protocol::skill::kCommand, leased);
  ASSERT_TRUE(controller_commands.wait_for_readers(1, 5s));
  ASSERT_TRUE(events_.wait_for_writers(1, 5s));
  send_with(controller_commands, "exec-1", "move", rigger_skill_SKILL_START, 1, "MoveArm");
  send_with(controller_commands, "exec-1", "look", rigger_skill_SKILL_START, 2, "Look");
  ASSERT_TRUE(loop_.run_until([&] { return starts_.size() == 2; }, 5s));
  ASSERT_TRUE(loop_.run_until([&] { return received_.size() == 2; }, 5s));
  EXPECT_EQ(shutdowns_.size(), 2u);
  for (const auto& e : received_) EXPECT_EQ(e.kind, rigger_skill_SKILL_EVENT_STOPPED) << e.node;
  EXPECT_TRUE(endpoint_->active_runs().empty());
}

TEST(ExecutorEndpointSetup, RejectsALibraryWithoutSkills) {
  testing::DomainLease domain;
  dds::Participant participant(domain.id());
  dds::EventLoop loop(participant);
  EXPECT_THROW(ExecutorEndpoint(participant, loop, null_logger(), "x", nlohmann::json::object(), {}),
               std::invalid_argument);
}

}  // namespace
}  // namespace rigger::skill_protocol

namespace rigger::skill_protocol {
namespace {

std::string answer_text(const Event& e) {
  const char* kind = e.kind == rigger_skill_SKILL_EVENT_PAUSED    ? "PAUSED"
                     : e.kind == rigger_skill_SKILL_EVENT_RESUMED ? "RESUMED"
                                                                  : "OTHER";
  return e.node + "#" + std::to_string(e.command_seq) + ":" + kind + ":" + e.kind_code;
}

// Every PAUSE / RESUME is answered: a pausable skill's run is handed to the skill and holds; a skill
// that is not pausable and holds no device keeps running, a monitor keeps monitoring; repeats, unknown
// nodes and runs being stopped get their own codes. The answers carry the START's seq, like the run's
// other events.
TEST_F(ExecutorEndpointTest, PauseAndResumeReachPausableSkillsOnlyAndAreAlwaysAnswered) {
  send("exec-1", "hoist", rigger_skill_SKILL_START, 1, "Hoist");
  send("exec-1", "move", rigger_skill_SKILL_START, 2, "Look");
  send("exec-1", "watch", rigger_skill_SKILL_START, 3, "Watch");
  ASSERT_TRUE(loop_.run_until([&] { return starts_.size() == 3; }, 5s));
  send("exec-1", "hoist", rigger_skill_SKILL_PAUSE, 4);
  send("exec-1", "move", rigger_skill_SKILL_PAUSE, 5);
  send("exec-1", "watch", rigger_skill_SKILL_PAUSE, 6);
  send("exec-1", "hoist", rigger_skill_SKILL_PAUSE, 7);
  send("exec-1", "hoist", rigger_skill_SKILL_RESUME, 8);
  send("exec-1", "ghost", rigger_skill_SKILL_RESUME, 9);
  send("exec-1", "move", rigger_skill_SKILL_SHUTDOWN, 10);
  send("exec-1", "move", rigger_skill_SKILL_PAUSE, 11);
  ASSERT_TRUE(loop_.run_until([&] { return received_.size() == 7; }, 5s));
  std::vector<std::string> answers;
  for (const auto& e : received_) answers.push_back(answer_text(e));
  EXPECT_EQ(answers,
            (std::vector<std::string>{"hoist#1:PAUSED:", "move#2:PAUSED:NOT_PAUSABLE", "watch#3:PAUSED:NOT_PAUSABLE",
                                      "hoist#1:PAUSED:ALREADY_PAUSED",
                                      "hoist#1:RESUMED:", "ghost#0:RESUMED:NOT_RUNNING", "move#2:PAUSED:STOPPING"}));
  EXPECT_NE(received_[1].message.find("Look cannot pause: it keeps running"), std::string::npos)
      << received_[1].message;
  EXPECT_NE(received_[2].message.find("Watch cannot pause: it keeps monitoring"), std::string::npos)
      << received_[2].message;
  EXPECT_EQ(received_[0].message, "Hoist holds");
  // The skill saw one PAUSE and one RESUME, of its own run.
  ASSERT_EQ(pauses_.size(), 2u);
  EXPECT_TRUE(pauses_[0].pause);
  EXPECT_FALSE(pauses_[1].pause);
  EXPECT_EQ(pauses_[0].run.start_seq, 1u);
  EXPECT_EQ(pauses_[0].reason, "test");
  // The answers are the endpoint's: a skill cannot send them.
  EXPECT_FALSE(endpoint_->report(starts_[0].run, EventKind::kPaused));
  EXPECT_FALSE(endpoint_->report(starts_[0].run, EventKind::kResumed));
  EXPECT_TRUE(endpoint_->report(starts_[0].run, EventKind::kSuccess));
}

// A PAUSE of a START that waits here for the stop of the node's previous run is answered at once and
// taken along: the run starts paused.
TEST_F(ExecutorEndpointTest, AStartThatWaitedWhilePausedStartsPaused) {
  send("exec-1", "hoist", rigger_skill_SKILL_START, 1, "Hoist");
  send("exec-1", "hoist", rigger_skill_SKILL_SHUTDOWN, 2, "Hoist");
  ASSERT_TRUE(loop_.run_until([&] { return shutdowns_.size() == 1; }, 5s));
  send("exec-1", "hoist", rigger_skill_SKILL_START, 3, "Hoist");
  send("exec-1", "hoist", rigger_skill_SKILL_PAUSE, 4);
  ASSERT_TRUE(loop_.run_until([&] { return received_.size() == 1; }, 5s));
  EXPECT_EQ(answer_text(received_[0]), "hoist#3:PAUSED:");
  EXPECT_NE(received_[0].message.find("will start paused"), std::string::npos) << received_[0].message;
  EXPECT_TRUE(pauses_.empty()) << "nothing runs yet to pause";
  EXPECT_TRUE(endpoint_->report(shutdowns_[0].run, EventKind::kStopped));
  ASSERT_TRUE(loop_.run_until([&] { return starts_.size() == 2 && pauses_.size() == 1; }, 5s));
  EXPECT_EQ(pauses_[0].run.start_seq, 3u);
  EXPECT_TRUE(pauses_[0].pause);
  // It was paused from its start: the RESUME reaches it.
  send("exec-1", "hoist", rigger_skill_SKILL_RESUME, 5);
  ASSERT_TRUE(loop_.run_until([&] { return pauses_.size() == 2; }, 5s));
  EXPECT_FALSE(pauses_[1].pause);
}

// A skill that cannot pause but holds a device (MoveArm: the robot) cannot hold it still: a PAUSE brings
// it to its safe stop. The answer says so, the skill gets a SHUTDOWN, and its stop ends the run as a
// FAILURE NOT_PAUSABLE (the controller never asked it to stop). A SHUTDOWN from the controller meanwhile
// makes the stop the answer to that SHUTDOWN again.
TEST_F(ExecutorEndpointTest, APauseBringsASkillThatCannotPauseButHoldsADeviceToItsSafeStop) {
  send("exec-1", "move", rigger_skill_SKILL_START, 1, "MoveArm");
  ASSERT_TRUE(loop_.run_until([&] { return starts_.size() == 1; }, 5s));
  send("exec-1", "move", rigger_skill_SKILL_PAUSE, 2);
  ASSERT_TRUE(loop_.run_until([&] { return shutdowns_.size() == 1 && received_.size() == 1; }, 5s));
  EXPECT_TRUE(pauses_.empty()) << "the skill is not asked to pause";
  EXPECT_EQ(shutdowns_[0].reason, "PAUSE: MoveArm cannot pause and holds robot: it is brought to its safe stop");
  EXPECT_EQ(answer_text(received_[0]), "move#1:PAUSED:NOT_PAUSABLE_STOPPED");
  EXPECT_EQ(received_[0].message, "MoveArm cannot pause and holds robot: it is brought to its safe stop");
  // A second PAUSE finds it stopping.
  send("exec-1", "move", rigger_skill_SKILL_PAUSE, 3);
  ASSERT_TRUE(loop_.run_until([&] { return received_.size() == 2; }, 5s));
  EXPECT_EQ(answer_text(received_[1]), "move#1:PAUSED:STOPPING");
  // Its safe stop reached: the node failed to pause.
  EXPECT_TRUE(endpoint_->report(shutdowns_[0].run, EventKind::kStopped, "", "arm at rest"));
  ASSERT_TRUE(loop_.run_until([&] { return received_.size() == 3; }, 5s));
  EXPECT_EQ(received_[2].node, "move");
  EXPECT_EQ(received_[2].kind, rigger_skill_SKILL_EVENT_FAILURE);
  EXPECT_EQ(received_[2].kind_code, "NOT_PAUSABLE");
  EXPECT_EQ(received_[2].message, "could not pause: arm at rest");

  // Weld, paused the same way, is cancelled by its controller meanwhile: its stop answers that SHUTDOWN.
  send("exec-1", "weld", rigger_skill_SKILL_START, 4, "Weld");
  ASSERT_TRUE(loop_.run_until([&] { return starts_.size() == 2; }, 5s));
  send("exec-1", "weld", rigger_skill_SKILL_PAUSE, 5);
  send("exec-1", "weld", rigger_skill_SKILL_SHUTDOWN, 6);
  ASSERT_TRUE(loop_.run_until([&] { return shutdowns_.size() == 3; }, 5s));
  EXPECT_TRUE(endpoint_->report(shutdowns_[1].run, EventKind::kStopped, "", "welder off"));
  ASSERT_TRUE(loop_.run_until([&] { return received_.size() == 5; }, 5s));
  EXPECT_EQ(answer_text(received_[3]), "weld#4:PAUSED:NOT_PAUSABLE_STOPPED");
  EXPECT_EQ(received_[4].node, "weld");
  EXPECT_EQ(received_[4].kind, rigger_skill_SKILL_EVENT_STOPPED);
  EXPECT_TRUE(endpoint_->active_runs().empty());
}

// Such a skill still waiting here to start (its node's previous run stops) when the PAUSE comes cannot
// start paused: it never starts, and its node fails NOT_PAUSABLE.
TEST_F(ExecutorEndpointTest, ASkillThatCannotPauseAndWaitsToStartNeverStartsWhenPaused) {
  send("exec-1", "move", rigger_skill_SKILL_START, 1, "MoveArm");
  send("exec-1", "move", rigger_skill_SKILL_SHUTDOWN, 2, "MoveArm");
  ASSERT_TRUE(loop_.run_until([&] { return shutdowns_.size() == 1; }, 5s));
  send("exec-1", "move", rigger_skill_SKILL_START, 3, "MoveArm");
  send("exec-1", "move", rigger_skill_SKILL_PAUSE, 4);
  ASSERT_TRUE(loop_.run_until([&] { return received_.size() == 2; }, 5s));
  EXPECT_EQ(answer_text(received_[0]), "move#3:PAUSED:NOT_PAUSABLE_STOPPED");
  EXPECT_EQ(received_[1].kind, rigger_skill_SKILL_EVENT_FAILURE);
  EXPECT_EQ(received_[1].kind_code, "NOT_PAUSABLE");
  EXPECT_EQ(received_[1].command_seq, 3u);
  EXPECT_NE(received_[1].message.find("it never started"), std::string::npos) << received_[1].message;
  // The first run's stop frees the node; nothing starts.
  EXPECT_TRUE(endpoint_->report(shutdowns_[0].run, EventKind::kStopped));
  ASSERT_TRUE(loop_.run_until([&] { return received_.size() == 3; }, 5s));
  loop_.run_until([] { return false; }, 100ms);
  EXPECT_EQ(starts_.size(), 1u);
}

}  // namespace
}  // namespace rigger::skill_protocol
