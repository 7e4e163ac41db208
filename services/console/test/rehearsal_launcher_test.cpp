// The rehearsal cell's launcher with shell scripts for the cell: idle -> starting -> ready -> idle stop,
// a command that exits, one that never brings a controller, one that cannot run, the console's stop, and
// a restart with another environment.
// Time is given to step(): the timeouts are crossed by passing a later time, never by waiting; the
// processes' ends are real, so those are awaited with a deadline.
#include <signal.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <sstream>

#include <gtest/gtest.h>

#include "rehearsal_launcher.hpp"

namespace rigger::console {
namespace {

using namespace std::chrono_literals;
using Clock = RehearsalLauncher::Clock;

class RehearsalLauncherTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = ::testing::TempDir() + "/rehearsal-launcher-" + std::to_string(::getpid()) + "-" +
           ::testing::UnitTest::GetInstance()->current_test_info()->name();
    std::filesystem::remove_all(dir_);  // no PID file of an earlier run (--gtest_repeat)
    std::filesystem::create_directories(dir_);
  }
  LaunchCommand shell(const std::string& script) {
    return {{"sh", "-c", script}, {"REHEARSAL_MARK=x"}, dir_, dir_ + "/cell.log", ""};
  }
  static LaunchTimes times() { return {10s, 5s, 5s}; }
  /// Steps until the launcher reaches `phase` (real processes end meanwhile); the changes seen, or the
  /// last ones when it did not within 10 s.
  std::vector<CellChange> step_until(RehearsalLauncher& l, CellPhase phase, Clock::time_point now, bool controller,
                                     bool busy) {
    std::vector<CellChange> seen;
    const auto deadline = Clock::now() + 10s;
    while (Clock::now() < deadline) {
      if (auto c = l.step(now, controller, busy)) seen.push_back(*c);
      if (l.phase() == phase) return seen;
      usleep(5000);  // polling real processes' ends with a deadline
    }
    ADD_FAILURE() << "still " << phase_name(l.phase());
    return seen;
  }
  /// The PID a script wrote to `file`, once it has.
  pid_t pid_in(const std::string& file) {
    const auto deadline = Clock::now() + 10s;
    while (Clock::now() < deadline) {
      std::ifstream in(dir_ + "/" + file);
      pid_t pid = 0;
      if (in >> pid && pid > 0) return pid;
      usleep(5000);
    }
    ADD_FAILURE() << "no pid in " << file;
    return 0;
  }
  std::string log() {
    std::ifstream in(dir_ + "/cell.log");
    std::stringstream text;
    text << in.rdbuf();
    return text.str();
  }
  static bool alive(pid_t pid) { return pid > 0 && kill(pid, 0) == 0; }

  std::string dir_;
};

// A script leading a background child stands for `rigger-compose supervise` and its services.
constexpr const char* kCell = "echo $REHEARSAL_MARK $RIGGER_DOMAIN; sleep 60 & echo $! > child.pid; wait";

TEST_F(RehearsalLauncherTest, StartsOnceBecomesReadyWithAControllerAndStopsItsWholeGroupWhenIdle) {
  RehearsalLauncher l(shell(kCell), times());
  const auto t0 = Clock::now();
  ASSERT_EQ(l.phase(), CellPhase::kIdle);
  const auto started = l.start(t0);
  ASSERT_TRUE(started && !started->failed);
  EXPECT_EQ(l.phase(), CellPhase::kStarting);
  EXPECT_NE(started->what.find("started (pid "), std::string::npos) << started->what;
  EXPECT_FALSE(l.start(t0)) << "a second start while starting starts nothing";
  const pid_t leader = l.status().value("pid", 0);
  const pid_t child = pid_in("child.pid");
  ASSERT_TRUE(alive(leader) && alive(child));
  EXPECT_EQ(getpgid(child), leader) << "the child runs in the group the leader leads";

  EXPECT_FALSE(l.step(t0 + 1s, false, false)) << "no controller yet: still starting";
  const auto ready = l.step(t0 + 2s, true, false);
  ASSERT_TRUE(ready);
  EXPECT_EQ(ready->phase, CellPhase::kReady);
  EXPECT_NE(ready->what.find("ready after 2.0 s"), std::string::npos) << ready->what;
  // Busy (a rehearsal runs, a page watches) well past the idle time: it stays; then idle for 5 s: it stops.
  EXPECT_FALSE(l.step(t0 + 30s, true, true));
  EXPECT_FALSE(l.step(t0 + 34s, true, false));
  const auto stopping = l.step(t0 + 35s, true, false);
  ASSERT_TRUE(stopping);
  EXPECT_EQ(stopping->phase, CellPhase::kStopping);
  EXPECT_NE(stopping->what.find("idle for 5.0 s"), std::string::npos) << stopping->what;
  EXPECT_FALSE(stopping->failed);
  const auto changes = step_until(l, CellPhase::kIdle, t0 + 36s, false, false);
  ASSERT_FALSE(changes.empty());
  EXPECT_NE(changes.back().what.find("stopped (pid " + std::to_string(leader)), std::string::npos);
  EXPECT_FALSE(alive(leader));
  EXPECT_FALSE(alive(child)) << "the leader's child outlived the stop";
  EXPECT_EQ(l.status()["error"], "");
  EXPECT_NE(log().find("\nx"), std::string::npos) << "the configured environment reaches it:\n" << log();
  // And again, on demand.
  ASSERT_TRUE(l.start(t0 + 40s));
  EXPECT_EQ(l.phase(), CellPhase::kStarting);
}

TEST_F(RehearsalLauncherTest, ACommandThatExitsBeforeAControllerIsThereIsAFailedStartNamingTheLog) {
  RehearsalLauncher l(shell("echo no cell today >&2; exit 3"), times());
  ASSERT_TRUE(l.start(Clock::now()));
  const auto changes = step_until(l, CellPhase::kIdle, Clock::now(), false, false);
  ASSERT_EQ(changes.size(), 1u);
  EXPECT_TRUE(changes[0].failed);
  EXPECT_NE(changes[0].what.find("exited with code 3 before the rehearsal cell was there"), std::string::npos)
      << changes[0].what;
  const std::string error = l.status()["error"];
  EXPECT_NE(error.find(dir_ + "/cell.log"), std::string::npos) << error;
  EXPECT_NE(log().find("no cell today"), std::string::npos) << log();
}

TEST_F(RehearsalLauncherTest, NoControllerWithinTheStartTimeoutStopsTheCellAndFails) {
  RehearsalLauncher l(shell(kCell), times());
  const auto t0 = Clock::now();
  ASSERT_TRUE(l.start(t0));
  const pid_t child = pid_in("child.pid");
  EXPECT_FALSE(l.step(t0 + 9s, false, false));
  const auto stopping = l.step(t0 + 10s, false, false);
  ASSERT_TRUE(stopping);
  EXPECT_TRUE(stopping->failed);
  EXPECT_NE(stopping->what.find("was not there within 10.0 s of the start"), std::string::npos) << stopping->what;
  step_until(l, CellPhase::kIdle, t0 + 11s, false, false);
  EXPECT_FALSE(alive(child));
  EXPECT_NE(l.status()["error"].get<std::string>().find("see " + dir_ + "/cell.log"), std::string::npos);
}

TEST_F(RehearsalLauncherTest, AProgramThatCannotRunFailsWithTheReasonInTheLog) {
  RehearsalLauncher l({{"no-such-rigger-program"}, {}, dir_, dir_ + "/cell.log", dir_}, times());
  ASSERT_TRUE(l.start(Clock::now()));
  const auto changes = step_until(l, CellPhase::kIdle, Clock::now(), false, false);
  ASSERT_EQ(changes.size(), 1u);
  EXPECT_NE(changes[0].what.find("exited with code 127"), std::string::npos) << changes[0].what;
  EXPECT_NE(log().find("cannot run no-such-rigger-program"), std::string::npos) << log();
  // Nothing configured at all: refused at once.
  RehearsalLauncher none({{}, {}, dir_, dir_ + "/cell.log", ""}, times());
  const auto refused = none.start(Clock::now());
  ASSERT_TRUE(refused && refused->failed);
  EXPECT_EQ(none.phase(), CellPhase::kIdle);
}

TEST_F(RehearsalLauncherTest, TheConsolesStopEndsTheWholeGroup) {
  pid_t leader = 0, child = 0;
  {
    RehearsalLauncher l(shell(kCell), times());
    ASSERT_TRUE(l.start(Clock::now()));
    leader = l.status().value("pid", 0);
    child = pid_in("child.pid");
    ASSERT_TRUE(alive(child));
  }
  EXPECT_FALSE(alive(leader));
  EXPECT_FALSE(alive(child));
}

// Restarted on another revision: the whole group ends, then it starts again with this start's environment
// over the command's own (RIGGER_CELL_FILE: the document it starts on).
TEST_F(RehearsalLauncherTest, ARestartEndsTheWholeGroupThenStartsWithItsOwnEnvironment) {
  RehearsalLauncher l(shell("echo cell=$RIGGER_CELL_FILE mark=$REHEARSAL_MARK; sleep 60 & echo $! > child.pid; wait"),
                      times());
  const auto t0 = Clock::now();
  ASSERT_TRUE(l.start(t0, {"RIGGER_CELL_FILE=/first/cell.json"}));
  const pid_t child = pid_in("child.pid");
  const pid_t leader = l.status().value("pid", 0);
  ASSERT_TRUE(l.step(t0 + 1s, true, false));
  ASSERT_EQ(l.phase(), CellPhase::kReady);
  std::filesystem::remove(dir_ + "/child.pid");
  const auto stopping = l.restart(t0 + 2s, {"RIGGER_CELL_FILE=/second/cell.json", "REHEARSAL_MARK=y"}, "a new load");
  ASSERT_TRUE(stopping);
  EXPECT_EQ(stopping->phase, CellPhase::kStopping);
  EXPECT_NE(stopping->what.find("a new load"), std::string::npos) << stopping->what;
  EXPECT_TRUE(l.restarting());
  EXPECT_EQ(l.status()["restart"], true);
  const auto changes = step_until(l, CellPhase::kStarting, t0 + 3s, false, false);
  ASSERT_FALSE(changes.empty());
  EXPECT_NE(changes.back().what.find("stopped (pid " + std::to_string(leader)), std::string::npos)
      << changes.back().what;
  EXPECT_NE(changes.back().what.find("; started (pid "), std::string::npos) << changes.back().what;
  EXPECT_FALSE(changes.back().failed);
  EXPECT_FALSE(alive(leader));
  EXPECT_FALSE(alive(child)) << "the first cell's child outlived the restart";
  EXPECT_FALSE(l.restarting());
  EXPECT_NE(l.status().value("pid", 0), leader);
  EXPECT_TRUE(alive(pid_in("child.pid")));
  EXPECT_NE(log().find("cell=/first/cell.json mark=x"), std::string::npos) << log();
  EXPECT_NE(log().find("cell=/second/cell.json mark=y"), std::string::npos) << log();
}

}  // namespace
}  // namespace rigger::console
