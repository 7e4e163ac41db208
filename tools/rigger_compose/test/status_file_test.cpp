#include "rigger/compose/status_file.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <fstream>

namespace rigger::compose {
namespace {

using ::testing::HasSubstr;

TEST(StatusFileTest, RoundTripsThroughJson) {
  SupervisorStatus st;
  st.supervisor_pid = 1234;
  st.domain = 17;
  st.compose_file = "/repo/deploy/compose.yaml";
  st.log_dir = "/tmp/x";
  st.phase = "running";
  st.failure = "";
  st.started_unix_ms = 1700000000000;
  st.updated_unix_ms = 1700000001000;
  ServiceStatusEntry e;
  e.name = "cell_sim";
  e.host = "localhost";
  e.state = "backoff";
  e.pid = 0;
  e.restarts = 3;
  e.started_unix_ms = 1700000000500;
  e.next_start_unix_ms = 1700000002000;
  e.last_exit = "killed by SIGKILL";
  st.services.push_back(e);
  e.name = "crane_gateway";
  e.local = false;
  e.state = "remote-ready";
  st.services.push_back(e);

  const auto back = status_from_json_text(to_json_text(st));
  EXPECT_EQ(back.supervisor_pid, 1234);
  EXPECT_EQ(back.domain, 17u);
  EXPECT_EQ(back.phase, "running");
  EXPECT_EQ(back.started_unix_ms, 1700000000000);
  ASSERT_EQ(back.services.size(), 2u);
  EXPECT_EQ(back.services[0].restarts, 3);
  EXPECT_EQ(back.services[0].last_exit, "killed by SIGKILL");
  EXPECT_EQ(back.services[0].next_start_unix_ms, 1700000002000);
  EXPECT_FALSE(back.services[1].local);
  EXPECT_EQ(back.find("crane_gateway")->state, "remote-ready");
  EXPECT_EQ(back.find("nope"), nullptr);
}

TEST(StatusFileTest, MalformedTextIsAnError) {
  EXPECT_THROW(status_from_json_text("{"), std::runtime_error);
  try {
    status_from_json_text("{\"supervisor_pid\": 1}");
    FAIL();
  } catch (const std::runtime_error& e) {
    EXPECT_THAT(e.what(), HasSubstr("malformed status file"));
  }
}

TEST(StatusFileTest, WritesAtomicallyAndReadsBack) {
  const std::string path = ::testing::TempDir() + "/status-" + std::to_string(getpid()) + ".json";
  SupervisorStatus st;
  st.phase = "starting";
  ASSERT_TRUE(write_status_file(path, st));
  st.phase = "running";
  ASSERT_TRUE(write_status_file(path, st));
  const auto back = read_status_file(path);
  ASSERT_TRUE(back);
  EXPECT_EQ(back->phase, "running");
  EXPECT_NE(access((path + ".tmp").c_str(), F_OK), 0);  // the temporary file was renamed away
  EXPECT_FALSE(read_status_file(path + ".missing"));
  std::ofstream(path) << "garbage";
  EXPECT_FALSE(read_status_file(path));
  unlink(path.c_str());
  EXPECT_FALSE(write_status_file("/nonexistent-dir/status.json", st));
}

TEST(StatusFileTest, MakeStatusConvertsSteadyTimesToWallClock) {
  ServiceDef def;
  def.name = "a";
  Supervision sup({{&def, true}});
  const auto t0 = Clock::time_point(std::chrono::seconds(1000));
  sup.begin(t0);
  sup.take_commands();
  sup.spawned("a", 42, t0);
  sup.announced_ready("a", 42, t0 + std::chrono::milliseconds(250));
  const auto st = make_status(sup, t0 + std::chrono::seconds(2), 1'000'000);
  EXPECT_EQ(st.phase, "running");
  ASSERT_EQ(st.services.size(), 1u);
  EXPECT_EQ(st.services[0].pid, 42);
  EXPECT_EQ(st.services[0].state, "ready");
  EXPECT_EQ(st.services[0].started_unix_ms, 1'000'000 - 2000);
  EXPECT_EQ(st.services[0].ready_unix_ms, 1'000'000 - 1750);
  EXPECT_EQ(st.started_unix_ms, 1'000'000 - 2000);
}

}  // namespace
}  // namespace rigger::compose
