// The harness's own tests, on the real echo service.
#include <signal.h>

#include <gtest/gtest-spi.h>
#include <gtest/gtest.h>

#include "rigger/testing/cell.hpp"

namespace rigger::testing {
namespace {

using namespace std::chrono_literals;

TEST(Harness, StartsWaitsForReadinessAndStopsCleanly) {
  Cell cell;
  cell.start("echo-a", "echo", {"--id", "echo-a"});
  ASSERT_TRUE(cell.wait_ready({"echo-a"}, 10s)) << cell.logs();
  EXPECT_GT(cell.process("echo-a").pid(), 0);
  const auto report = cell.stop_all();
  EXPECT_TRUE(report.ok) << report.problems;
  EXPECT_NE(cell.process("echo-a").log().find("ready service=echo-a"), std::string::npos);
  EXPECT_NE(cell.process("echo-a").log().find("stopped service=echo-a"), std::string::npos);
}

TEST(Harness, WaitReadyFailsFastWhenAProcessDies) {
  Cell cell;
  cell.start("broken", "echo", {"--id", "broken", "--config", "/nonexistent.json"});
  ::testing::TestPartResultArray failures;
  bool ready = true;
  const auto start = std::chrono::steady_clock::now();
  {
    ::testing::ScopedFakeTestPartResultReporter reporter(
        ::testing::ScopedFakeTestPartResultReporter::INTERCEPT_ONLY_CURRENT_THREAD, &failures);
    ready = cell.wait_ready({"broken"}, 20s);
  }
  EXPECT_FALSE(ready);
  EXPECT_LT(std::chrono::steady_clock::now() - start, 10s) << "did not notice the exit before the timeout";
  ASSERT_EQ(failures.size(), 1);
  EXPECT_NE(std::string(failures.GetTestPartResult(0).message()).find("exit code 2"), std::string::npos);
  EXPECT_FALSE(cell.stop_all().ok);
}

TEST(Harness, StopReportsAProcessKilledBySignal) {
  Cell cell;
  cell.start("victim", "echo", {"--id", "victim"});
  ASSERT_TRUE(cell.wait_ready({"victim"}, 10s)) << cell.logs();
  const auto st = cell.stop("victim", SIGKILL, 5s);
  ASSERT_TRUE(st.has_value());
  EXPECT_FALSE(st->exited);
  EXPECT_EQ(st->signal, SIGKILL);
}

TEST(Harness, ParallelCellsGetDistinctDomains) {
  Cell a;
  Cell b;
  EXPECT_NE(a.domain_id(), b.domain_id());
  a.start("echo-a", "echo", {"--id", "same-id"});
  b.start("echo-b", "echo", {"--id", "same-id"});
  ASSERT_TRUE(a.wait_ready({"same-id"}, 10s));
  ASSERT_TRUE(b.wait_ready({"same-id"}, 10s));
  // Each cell sees only its own process.
  EXPECT_EQ(a.directory().services().at("same-id").pid, a.process("echo-a").pid());
  EXPECT_EQ(b.directory().services().at("same-id").pid, b.process("echo-b").pid());
  EXPECT_TRUE(a.stop_all().ok);
  EXPECT_TRUE(b.stop_all().ok);
}

}  // namespace
}  // namespace rigger::testing
