// Parallel(M, K) with typed counting, checked exhaustively against an independent oracle.

#include <algorithm>
#include <numeric>
#include <random>
#include <set>
#include <sstream>

#include <gtest/gtest.h>

#include "fake_port.hpp"

namespace rigger::bt {
namespace {

using namespace build;
using testing::Harness;

// What a child does in a scenario.
enum class Outcome {
  kSucceed,        // skill: SUCCESS
  kFail,           // FAILURE
  kSilent,         // never reports before the parallel decides
  kMonitorSuccess  // monitor reports SUCCESS: a protocol error, counts as a failure
};

struct Expectation {
  bool decided = false;
  bool success = false;
  std::size_t decided_after = 0;  // number of events in `order` delivered when the decision fell
};

// The oracle states the Parallel rule directly on prefixes of the event order: the decision falls after
// the shortest prefix in which M successes, or K failures, or "successes + skills that have not
// reported yet < M" holds. Monitors never count as possible successes.
Expectation oracle(std::size_t skills, std::size_t m, std::size_t k, const std::vector<Outcome>& outcomes,
                   const std::vector<std::size_t>& order) {
  for (std::size_t prefix = 1; prefix <= order.size(); ++prefix) {
    std::size_t successes = 0;
    std::size_t failures = 0;
    std::size_t skills_reported = 0;
    for (std::size_t i = 0; i < prefix; ++i) {
      const std::size_t child = order[i];
      (outcomes[child] == Outcome::kSucceed ? successes : failures) += 1;
      skills_reported += child < skills ? 1 : 0;
    }
    const std::size_t skills_pending = skills - skills_reported;
    if (successes >= m || failures >= k || successes + skills_pending < m) {
      return {true, successes >= m, prefix};
    }
  }
  return {};
}

std::string describe(std::size_t skills, std::size_t monitors, std::size_t m, std::size_t k,
                     const std::vector<Outcome>& outcomes, const std::vector<std::size_t>& order) {
  std::ostringstream out;
  out << skills << " skills, " << monitors << " monitors, M=" << m << " K=" << k << ", outcomes:";
  for (const auto o : outcomes) {
    out << " " << (o == Outcome::kSucceed ? "S" : o == Outcome::kFail ? "F" : o == Outcome::kSilent ? "-" : "P");
  }
  out << ", order:";
  for (const auto c : order) {
    out << " " << c;
  }
  return out.str();
}

// Runs one scenario and checks the engine against the oracle. Returns false on the first mismatch
// (the EXPECTs already say what).
bool run_scenario(std::size_t skills, std::size_t monitors, std::size_t m, std::size_t k,
                  const std::vector<Outcome>& outcomes, const std::vector<std::size_t>& order) {
  std::vector<Node> children;
  for (std::size_t i = 0; i < skills; ++i) {
    children.push_back(skill("S" + std::to_string(i)));
  }
  for (std::size_t i = 0; i < monitors; ++i) {
    children.push_back(monitor("M" + std::to_string(i)));
  }
  Harness h(parallel(m, k, std::move(children)));
  h.engine->start();
  const std::string what = describe(skills, monitors, m, k, outcomes, order);
  const Expectation expected = oracle(skills, m, k, outcomes, order);
  const std::size_t n = skills + monitors;
  auto id = [](std::size_t child) { return "root/" + std::to_string(child); };

  bool ok = true;
  auto check = [&](bool condition, const std::string& message) {
    if (!condition) {
      ADD_FAILURE() << message << " in scenario: " << what;
      ok = false;
    }
  };

  check(h.port.starts().size() == n, "every child starts at once");
  for (std::size_t i = 0; i < order.size() && ok; ++i) {
    const std::size_t child = order[i];
    const bool before_decision = !expected.decided || i < expected.decided_after;
    if (before_decision) {
      check(h.state("root") == NodeState::kRunning && h.port.shutdowns().empty(),
            "parallel decided early, before event " + std::to_string(i));
      check(h.state(id(child)) == NodeState::kRunning, "child not running before its event");
    } else {
      // Decided: the child was shut down and its own result races the SHUTDOWN.
      check(h.state(id(child)) == NodeState::kStopping, "child not stopping after the decision");
    }
    const auto r = outcomes[child] == Outcome::kSucceed || outcomes[child] == Outcome::kMonitorSuccess
                       ? h.succeed(id(child))
                       : h.fail(id(child), "CODE" + std::to_string(child));
    check(r.acted_on(), "event refused: " + r.reason);
    if (outcomes[child] == Outcome::kMonitorSuccess) {
      check(r.status == EventStatus::kProtocolError, "monitor SUCCESS not flagged as protocol error");
    }
  }
  if (!ok) {
    return false;
  }
  if (!expected.decided) {
    check(h.state("root") == NodeState::kRunning, "parallel decided although the oracle did not");
    check(h.port.shutdowns().empty(), "shutdown sent without a decision");
    return ok;
  }
  // Exactly the children that had not reported when the decision fell were shut down.
  std::set<std::string> expected_shutdowns;
  for (std::size_t c = 0; c < n; ++c) {
    const auto pos = std::find(order.begin(), order.end(), c) - order.begin();
    if (static_cast<std::size_t>(pos) >= expected.decided_after) {
      expected_shutdowns.insert(id(c));
    }
  }
  const std::set<std::string> shutdowns(h.port.shutdowns().begin(), h.port.shutdowns().end());
  check(shutdowns == expected_shutdowns, "wrong set of children shut down");
  check(h.port.shutdowns().size() == shutdowns.size(), "a child was shut down twice");

  // Two-phase: the parallel reports only after every shut-down child answered.
  const auto stopping_left = [&] {
    std::size_t count = 0;
    for (std::size_t c = 0; c < n; ++c) {
      count += h.state(id(c)) == NodeState::kStopping ? 1 : 0;
    }
    return count;
  };
  while (stopping_left() > 0) {
    check(h.state("root") == NodeState::kRunning, "parallel reported before its children stopped");
    for (std::size_t c = 0; c < n; ++c) {
      if (h.state(id(c)) == NodeState::kStopping) {
        check(h.stopped(id(c)).acted_on(), "STOPPED refused");
        break;
      }
    }
  }
  check(h.state("root") == (expected.success ? NodeState::kSuccess : NodeState::kFailure), "wrong result");
  check(h.port.finished_count() == 1, "task not finished exactly once");
  if (!expected.success && h.port.result()) {
    // The failure names the child whose event decided it.
    const std::size_t decisive = order[expected.decided_after - 1];
    check(h.port.result()->origin == id(decisive), "wrong failure origin " + h.port.result()->origin);
  }
  return ok;
}

std::vector<std::vector<std::size_t>> orderings(std::vector<std::size_t> reporters, std::mt19937& rng) {
  std::vector<std::vector<std::size_t>> out;
  std::sort(reporters.begin(), reporters.end());
  if (reporters.size() <= 4) {
    do {
      out.push_back(reporters);
    } while (std::next_permutation(reporters.begin(), reporters.end()));
    return out;
  }
  out.push_back(reporters);
  out.emplace_back(reporters.rbegin(), reporters.rend());
  for (int i = 0; i < 10; ++i) {
    std::shuffle(reporters.begin(), reporters.end(), rng);
    out.push_back(reporters);
  }
  return out;
}

TEST(EngineParallel, EveryThresholdCombinationMatchesOracle) {
  std::mt19937 rng(20240611);
  std::size_t scenarios = 0;
  for (std::size_t skills = 1; skills <= 3; ++skills) {
    for (std::size_t monitors = 0; monitors <= 3; ++monitors) {
      const std::size_t n = skills + monitors;
      const std::vector<Outcome> skill_outcomes{Outcome::kSucceed, Outcome::kFail, Outcome::kSilent};
      const std::vector<Outcome> monitor_outcomes{Outcome::kFail, Outcome::kSilent, Outcome::kMonitorSuccess};
      std::size_t combos = 1;
      for (std::size_t i = 0; i < skills; ++i) combos *= skill_outcomes.size();
      for (std::size_t i = 0; i < monitors; ++i) combos *= monitor_outcomes.size();
      for (std::size_t combo = 0; combo < combos; ++combo) {
        std::vector<Outcome> outcomes(n);
        std::size_t rest = combo;
        for (std::size_t c = 0; c < n; ++c) {
          const auto& choices = c < skills ? skill_outcomes : monitor_outcomes;
          outcomes[c] = choices[rest % choices.size()];
          rest /= choices.size();
        }
        std::vector<std::size_t> reporters;
        for (std::size_t c = 0; c < n; ++c) {
          if (outcomes[c] != Outcome::kSilent) {
            reporters.push_back(c);
          }
        }
        for (const auto& order : orderings(reporters, rng)) {
          for (std::size_t m = 1; m <= skills; ++m) {
            for (std::size_t k = 1; k <= n; ++k) {
              ++scenarios;
              if (!run_scenario(skills, monitors, m, k, outcomes, order)) {
                return;  // one detailed failure is enough
              }
            }
          }
        }
      }
    }
  }
  EXPECT_GT(scenarios, 50000U);
}

TEST(EngineParallel, PaperPatternSkillWithThreeMonitors) {
  // Parallel(M=1, K=1): succeeds when the skill does, fails the instant a monitor fires.
  {
    Harness h(parallel(1, 1, {skill("AttachRobotToLoad"), monitor("YankMonitor"), monitor("ForceMonitor"),
                               monitor("TimerMonitor")}));
    h.engine->start();
    h.succeed("root/0");
    EXPECT_EQ(h.port.shutdowns(), (std::vector<std::string>{"root/1", "root/2", "root/3"}));
    h.stop_all_stopping();
    EXPECT_EQ(h.port.result()->outcome, TaskOutcome::kSucceeded);
  }
  {
    Harness h(parallel(1, 1, {skill("AttachRobotToLoad"), monitor("YankMonitor"), monitor("ForceMonitor"),
                               monitor("TimerMonitor")}));
    h.engine->start();
    h.fail("root/1", "YANK_DETECTED");
    EXPECT_EQ(h.port.shutdowns(), (std::vector<std::string>{"root/0", "root/2", "root/3"}));
    EXPECT_EQ(h.state("root"), NodeState::kRunning);
    h.stop_all_stopping();
    EXPECT_EQ(h.port.result()->code, "YANK_DETECTED");
    EXPECT_EQ(h.port.result()->origin, "root/1");
    // The skill acknowledged its shutdown before the parallel reported.
    EXPECT_LT(h.port.position("state root/0 STOPPED"), h.port.position("state root FAILURE"));
  }
}

TEST(EngineParallel, SubtreesCountTowardsMButMonitorOnlySubtreesDoNot) {
  // Children: a Sequence (can succeed), a Timeout around a monitor (cannot), a skill.
  Harness h(parallel(2, 3, {sequence({skill("A"), skill("B")}), timeout(100.0, monitor("M")), skill("C")}));
  EXPECT_FALSE(h.engine->can_succeed()[h.index("root/1")]);
  h.engine->start();
  h.fail("root/2", "C_FAILED");
  // M=2 needs both the sequence and C: unreachable after C failed, so it fails at once.
  EXPECT_EQ(h.state("root/0/0"), NodeState::kStopping);
  EXPECT_EQ(h.state("root/1/0"), NodeState::kStopping);
  h.stop_all_stopping();
  EXPECT_EQ(h.port.result()->code, "C_FAILED");
  EXPECT_NE(h.port.result()->message.find("no longer reachable"), std::string::npos);
}

TEST(EngineParallel, ThousandMonitorsBesideOneSkill) {
  std::vector<Node> children{skill("CollaborativeMoveLoad")};
  for (int i = 0; i < 1000; ++i) {
    children.push_back(monitor("ForceMonitor"));
  }
  {
    Harness h(parallel(1, 1, children));
    h.engine->start();
    EXPECT_EQ(h.port.starts().size(), 1001U);
    h.succeed("root/0");
    EXPECT_EQ(h.port.shutdowns().size(), 1000U);
    EXPECT_EQ(h.engine->pending_timers(), 1000U);
    h.stop_all_stopping();
    EXPECT_EQ(h.port.result()->outcome, TaskOutcome::kSucceeded);
    EXPECT_EQ(h.engine->pending_timers(), 0U);
  }
  {
    Harness h(parallel(1, 1, children));
    h.engine->start();
    h.fail("root/500", "FORCE_LIMIT");
    EXPECT_EQ(h.port.shutdowns().size(), 1000U);
    EXPECT_EQ(h.port.shutdowns().front(), "root/0");
    h.stop_all_stopping();
    EXPECT_EQ(h.port.result()->origin, "root/500");
  }
  {
    // K = 3: two monitors firing are not enough.
    Harness h(parallel(1, 3, children));
    h.engine->start();
    h.fail("root/10");
    h.fail("root/20");
    EXPECT_TRUE(h.port.shutdowns().empty());
    h.fail("root/30", "THIRD");
    EXPECT_EQ(h.port.shutdowns().size(), 998U);
  }
}

}  // namespace
}  // namespace rigger::bt
