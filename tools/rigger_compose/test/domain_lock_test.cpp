// The supervisor's lock: one per DDS domain and host. Hosts that share a file system (the network
// namespaces of deploy/lab-hosts) each hold their own; two supervisors for one host never run at once.
#include <unistd.h>

#include <gtest/gtest.h>

#include "rigger/compose/process_util.hpp"

namespace rigger::compose {
namespace {

// A domain id no cell of the test suite uses (the harness leases 20..230).
constexpr std::uint32_t kDomain = 231;

TEST(DomainLock, OnePerDomainAndHost) {
  DomainLock devices(kDomain, "devices");
  ASSERT_TRUE(devices.try_lock("/tmp/devices-logs"));
  DomainLock again(kDomain, "devices");
  EXPECT_FALSE(again.try_lock("/tmp/other")) << "two supervisors for one host and domain";

  DomainLock skills(kDomain, "skills");
  EXPECT_TRUE(skills.try_lock("/tmp/skills-logs")) << "another host of the same machine must get its own";

  const auto holder = DomainLock::holder(kDomain, "devices");
  ASSERT_TRUE(holder.has_value());
  EXPECT_EQ(holder->pid, getpid());
  EXPECT_EQ(holder->log_dir, "/tmp/devices-logs");
  EXPECT_FALSE(DomainLock::holder(kDomain).has_value()) << "the machine's own lock is a third one";
  EXPECT_NE(DomainLock::path(kDomain, "devices"), DomainLock::path(kDomain));
}

}  // namespace
}  // namespace rigger::compose
