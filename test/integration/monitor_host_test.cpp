// monitor_host as a real process: the test publishes a wrench stream (as the robot driver would) and
// acts as the controller with raw SkillCommand writes, then checks the SkillEvents the host reports.
#include <map>
#include <set>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "rigger/dds/conversions.hpp"
#include "rigger/dds/pubsub.hpp"
#include "rigger/protocol/robot.hpp"
#include "rigger/protocol/skill.hpp"
#include "rigger/testing/cell.hpp"
#include "skill_command_support.hpp"

namespace rigger::testing {
namespace {

using namespace std::chrono_literals;

constexpr const char* kHost = "monitors-1";

struct Event {
  std::string node, code, message;
  rigger_skill_SkillEventKind kind;
  std::uint64_t command_seq;
};

class MonitorHostTest : public MultiProcessTest {
 protected:
  void SetUp() override {
    commands_ =
        std::make_unique<dds::Writer<rigger_skill_SkillCommand>>(cell_.participant(), protocol::skill::kCommand);
    events_ = std::make_unique<dds::Reader<rigger_skill_SkillEvent>>(cell_.participant(), protocol::skill::kEvent);
    wrench_ =
        std::make_unique<dds::Writer<rigger_sensing_WrenchStamped>>(cell_.participant(), protocol::robot::kWrench);
    cell_.loop().on_data(*events_, [this] {
      events_->take([this](const rigger_skill_SkillEvent& e, const dds_sample_info_t&) {
        if (e.kind == rigger_skill_SKILL_EVENT_ACCEPTED) return;  // the host's answer to a START, not the monitor's
        events_by_node_[dds::to_string(e.node_id)].push_back(
            {dds::to_string(e.node_id), dds::to_string(e.code), dds::to_string(e.message), e.kind, e.command_seq});
        ++event_count_;
      });
    });
    cell_.start(kHost, "monitor_host", {"--id", kHost});
    ASSERT_TRUE(cell_.wait_ready({kHost}, 10s));
    ASSERT_TRUE(commands_->wait_for_readers(1, 10s));
    ASSERT_TRUE(wrench_->wait_for_readers(1, 10s));
    ASSERT_TRUE(events_->wait_for_writers(1, 10s));  // the host's replies are volatile
  }

  void TearDown() override {
    if (stream_timer_ != 0) cell_.loop().cancel(stream_timer_);
    MultiProcessTest::TearDown();
  }

  std::uint64_t send(const std::string& node, rigger_skill_SkillCommandKind kind, const std::string& monitor,
                     const nlohmann::json& params = nlohmann::json::object()) {
    const std::uint64_t seq = ++seq_;
    EXPECT_EQ(write_skill_command(*commands_, {kHost, "t1", node, monitor, kind, params.dump(), "test", seq}),
              DDS_RETCODE_OK);
    return seq;
  }

  /// Publishes the force (N, along z) every `period`, stamped now; counts samples.
  void start_stream(std::chrono::milliseconds period = 2ms) {
    stream_timer_ = cell_.loop().every(period, [this] {
      rigger_sensing_WrenchStamped w{};
      const std::string frame = "ft_sensor";
      w.header.stamp = dds::wire_now();
      w.header.frame_id = dds::wire_string(frame);
      w.wrench.force.z = force_n_;
      wrench_->write(w);
      ++samples_;
    });
  }
  void stop_stream() {
    cell_.loop().cancel(stream_timer_);
    stream_timer_ = 0;
  }
  /// Runs the stream for `n` more samples (the test's clock; nothing waits on the monitor host).
  void run_samples(std::uint64_t n) {
    const auto target = samples_ + n;
    ASSERT_TRUE(cell_.wait_until([&] { return samples_ >= target; }, 10s));
  }
  const Event* last_event(const std::string& node) {
    auto it = events_by_node_.find(node);
    return it == events_by_node_.end() || it->second.empty() ? nullptr : &it->second.back();
  }
  const Event* wait_event(const std::string& node, std::chrono::milliseconds timeout = 5s) {
    cell_.wait_until([&] { return last_event(node) != nullptr; }, timeout);
    return last_event(node);
  }

  std::unique_ptr<dds::Writer<rigger_skill_SkillCommand>> commands_;
  std::unique_ptr<dds::Reader<rigger_skill_SkillEvent>> events_;
  std::unique_ptr<dds::Writer<rigger_sensing_WrenchStamped>> wrench_;
  std::map<std::string, std::vector<Event>> events_by_node_;
  std::size_t event_count_ = 0;
  std::uint64_t seq_ = 0;
  dds::EventLoop::TimerId stream_timer_ = 0;
  double force_n_ = 0.0;
  std::uint64_t samples_ = 0;
};

TEST_F(MonitorHostTest, ForceMonitorFiresOnAForceStep) {
  force_n_ = 5.0;
  start_stream();
  const auto start_seq = send("force", rigger_skill_SKILL_START, "ForceMonitor", {{"max_force_n", 50.0}, {"dwell_s", 0.02}});
  run_samples(100);
  EXPECT_EQ(last_event("force"), nullptr) << "fired below the limit: " << last_event("force")->code;
  force_n_ = 120.0;
  const Event* e = wait_event("force");
  ASSERT_NE(e, nullptr);
  EXPECT_EQ(e->kind, rigger_skill_SKILL_EVENT_FAILURE);
  EXPECT_EQ(e->code, "FORCE_LIMIT");
  EXPECT_EQ(e->command_seq, start_seq);
  EXPECT_EQ(events_by_node_["force"].size(), 1u);
}

TEST_F(MonitorHostTest, YankMonitorFiresOnASlipSpike) {
  force_n_ = 20.0;  // a held load
  start_stream();
  send("yank", rigger_skill_SKILL_START, "YankMonitor", {{"max_yank_n_per_s", 400.0}});
  run_samples(150);
  EXPECT_EQ(last_event("yank"), nullptr);
  force_n_ = 0.0;  // the grasp slips: the load's weight leaves the sensor in one sample
  const Event* e = wait_event("yank");
  ASSERT_NE(e, nullptr);
  EXPECT_EQ(e->kind, rigger_skill_SKILL_EVENT_FAILURE);
  EXPECT_EQ(e->code, "YANK_LIMIT");
}

TEST_F(MonitorHostTest, StreamStoppingFiresSensorStale) {
  force_n_ = 1.0;
  start_stream();
  send("stale", rigger_skill_SKILL_START, "ForceMonitor", {{"max_force_n", 50.0}, {"max_sample_age_s", 0.1}});
  run_samples(100);
  EXPECT_EQ(last_event("stale"), nullptr);
  stop_stream();
  const Event* e = wait_event("stale");
  ASSERT_NE(e, nullptr);
  EXPECT_EQ(e->kind, rigger_skill_SKILL_EVENT_FAILURE);
  EXPECT_EQ(e->code, "SENSOR_STALE");
}

TEST_F(MonitorHostTest, NoStreamAtAllFiresSensorStale) {
  send("never", rigger_skill_SKILL_START, "YankMonitor", {{"max_yank_n_per_s", 400.0}, {"max_sample_age_s", 0.05}});
  const Event* e = wait_event("never");
  ASSERT_NE(e, nullptr);
  EXPECT_EQ(e->code, "SENSOR_STALE");
}

TEST_F(MonitorHostTest, TimerMonitorFiresTimeoutAfterItsDuration) {
  const auto t0 = std::chrono::steady_clock::now();
  send("timer", rigger_skill_SKILL_START, "TimerMonitor", {{"duration_s", 0.3}});
  const Event* e = wait_event("timer");
  ASSERT_NE(e, nullptr);
  EXPECT_EQ(e->code, "TIMEOUT");
  EXPECT_GE(std::chrono::steady_clock::now() - t0, 300ms);
}

TEST_F(MonitorHostTest, ShutdownAnswersStoppedAndTheMonitorIsDisarmed) {
  force_n_ = 5.0;
  start_stream();
  send("force", rigger_skill_SKILL_START, "ForceMonitor", {{"max_force_n", 50.0}});
  run_samples(50);
  send("force", rigger_skill_SKILL_SHUTDOWN, "ForceMonitor");
  const Event* e = wait_event("force");
  ASSERT_NE(e, nullptr);
  EXPECT_EQ(e->kind, rigger_skill_SKILL_EVENT_STOPPED);
  EXPECT_EQ(e->code, "");  // it was running: not NOT_RUNNING
  // Disarmed: a force step afterwards reports nothing more.
  force_n_ = 500.0;
  run_samples(100);
  EXPECT_EQ(events_by_node_["force"].size(), 1u);
}

TEST_F(MonitorHostTest, BadParamsFailWithTheMessage) {
  send("bad", rigger_skill_SKILL_START, "ForceMonitor", {{"max_force_n", -3.0}, {"dwel_s", 1}});
  const Event* e = wait_event("bad");
  ASSERT_NE(e, nullptr);
  EXPECT_EQ(e->kind, rigger_skill_SKILL_EVENT_FAILURE);
  EXPECT_EQ(e->code, "BAD_PARAMS");
  EXPECT_NE(e->message.find("/max_force_n"), std::string::npos) << e->message;
  EXPECT_NE(e->message.find("/dwel_s"), std::string::npos) << e->message;
  send("unknown", rigger_skill_SKILL_START, "SpeedMonitor");
  const Event* u = wait_event("unknown");
  ASSERT_NE(u, nullptr);
  EXPECT_EQ(u->code, "UNKNOWN_SKILL");
}

TEST_F(MonitorHostTest, AThousandConcurrentMonitorsAllFire) {
  constexpr int kMonitors = 1000;
  force_n_ = 5.0;
  start_stream();
  for (int i = 0; i < kMonitors; ++i)
    send("m" + std::to_string(i), rigger_skill_SKILL_START, "ForceMonitor", {{"max_force_n", 50.0}, {"max_sample_age_s", 2.0}});
  run_samples(200);
  EXPECT_EQ(event_count_, 0u) << "a monitor fired below its limit";
  force_n_ = 200.0;
  ASSERT_TRUE(cell_.wait_until([&] { return event_count_ >= kMonitors; }, 20s)) << event_count_ << " events";
  std::set<std::string> codes;
  for (const auto& [node, events] : events_by_node_) {
    ASSERT_EQ(events.size(), 1u) << node;
    codes.insert(events[0].code);
  }
  EXPECT_EQ(events_by_node_.size(), static_cast<std::size_t>(kMonitors));
  EXPECT_EQ(codes, std::set<std::string>{"FORCE_LIMIT"});
}

}  // namespace
}  // namespace rigger::testing
