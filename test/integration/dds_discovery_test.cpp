// Acceptance of the foundation: on loopback only, 24 processes discover each other within
// 3 s on a private domain, and the loss of one (SIGKILL, or hung under SIGSTOP) is seen by the others in
// under 1 s. Each echo process publishes the READY services it sees on rigger/system/peer_view.
#include <signal.h>

#include <map>
#include <set>

#include <gtest/gtest.h>

#include "rigger/dds/conversions.hpp"
#include "rigger/dds/pubsub.hpp"
#include "rigger/protocol/system.hpp"
#include "rigger/testing/cell.hpp"

namespace rigger::testing {
namespace {

using namespace std::chrono_literals;
using Clock = std::chrono::steady_clock;

class DdsDiscoveryTest : public MultiProcessTest {
 protected:
  void SetUp() override {
    views_ = std::make_unique<dds::Reader<rigger_system_PeerView>>(cell_.participant(), protocol::system::kPeerView);
    cell_.loop().on_data(*views_, [this] {
      views_->take([this](const rigger_system_PeerView& v, const dds_sample_info_t&) {
        auto peers = dds::to_string_vector(v.alive_peers);
        view_[dds::to_string(v.observer_id)] = std::set<std::string>(peers.begin(), peers.end());
      });
    });
  }

  std::vector<std::string> start_echoes(int n) {
    std::vector<std::string> ids;
    for (int i = 0; i < n; ++i) {
      ids.push_back("echo-" + std::to_string(i));
      cell_.start(ids.back(), "echo", {"--id", ids.back()});
    }
    return ids;
  }

  /// Who misses whom, for failure messages.
  std::string differences(const std::vector<std::string>& observers, const std::set<std::string>& expected) {
    std::string out;
    for (const auto& o : observers) {
      auto it = view_.find(o);
      if (it == view_.end()) {
        out += o + ": no view\n";
        continue;
      }
      for (const auto& e : expected)
        if (!it->second.count(e)) out += o + " misses " + e + "\n";
      for (const auto& x : it->second)
        if (!expected.count(x)) out += o + " still sees " + x + "\n";
    }
    return out;
  }

  /// Every observer in `observers` sees exactly `expected`.
  bool all_see(const std::vector<std::string>& observers, const std::set<std::string>& expected) {
    for (const auto& o : observers) {
      auto it = view_.find(o);
      if (it == view_.end() || it->second != expected) return false;
    }
    return true;
  }

  std::unique_ptr<dds::Reader<rigger_system_PeerView>> views_;
  std::map<std::string, std::set<std::string>> view_;
};

TEST_F(DdsDiscoveryTest, TwentyFourProcessesSeeEachOtherWithinThreeSeconds) {
  const auto t0 = Clock::now();
  const auto ids = start_echoes(24);
  const std::set<std::string> everyone(ids.begin(), ids.end());
  const bool ok = cell_.wait_until([&] { return all_see(ids, everyone); }, 10s);
  const auto took = std::chrono::duration_cast<std::chrono::milliseconds>(Clock::now() - t0);
  RecordProperty("discovery_ms", static_cast<int>(took.count()));
  std::cout << "24 processes: all see all 24 after " << took.count() << " ms (from the first spawn)\n";
  ASSERT_TRUE(ok) << "not every process saw all 24 within 10 s:\n" << differences(ids, everyone);
  EXPECT_LT(took, 3s);
}

TEST_F(DdsDiscoveryTest, KilledProcessIsSeenLostInUnderOneSecond) {
  const auto ids = start_echoes(6);
  const std::set<std::string> everyone(ids.begin(), ids.end());
  ASSERT_TRUE(cell_.wait_until([&] { return all_see(ids, everyone); }, 10s));

  const std::string victim = ids.back();
  std::vector<std::string> survivors(ids.begin(), ids.end() - 1);
  std::set<std::string> rest(survivors.begin(), survivors.end());
  const auto t0 = Clock::now();
  ASSERT_TRUE(cell_.stop(victim, SIGKILL, 5s).has_value());
  const bool ok = cell_.wait_until([&] { return all_see(survivors, rest) && !cell_.directory().is_ready(victim); }, 5s);
  const auto took = std::chrono::duration_cast<std::chrono::milliseconds>(Clock::now() - t0);
  std::cout << "SIGKILL: loss seen by all 5 survivors and the test after " << took.count() << " ms\n";
  ASSERT_TRUE(ok);
  EXPECT_LT(took, 1s);
}

TEST_F(DdsDiscoveryTest, HungProcessIsSeenLostInUnderOneSecond) {
  const auto ids = start_echoes(3);
  const std::set<std::string> everyone(ids.begin(), ids.end());
  ASSERT_TRUE(cell_.wait_until([&] { return all_see(ids, everyone); }, 10s));

  const std::string victim = ids.back();
  std::vector<std::string> survivors(ids.begin(), ids.end() - 1);
  std::set<std::string> rest(survivors.begin(), survivors.end());
  const auto t0 = Clock::now();
  ASSERT_TRUE(cell_.process(victim).signal(SIGSTOP));  // alive, but its work loop no longer runs
  const bool ok = cell_.wait_until([&] { return all_see(survivors, rest); }, 5s);
  const auto took = std::chrono::duration_cast<std::chrono::milliseconds>(Clock::now() - t0);
  std::cout << "SIGSTOP: loss seen by both survivors after " << took.count() << " ms\n";
  cell_.process(victim).signal(SIGCONT);
  ASSERT_TRUE(ok);
  EXPECT_LT(took, 1s);
  // Resumed, it is seen again: the loss was liveliness, not a crash.
  EXPECT_TRUE(cell_.wait_until([&] { return all_see(ids, everyone); }, 10s));
}

}  // namespace
}  // namespace rigger::testing
