#include "rigger/service/service_state.hpp"

#include <gtest/gtest.h>

#include "rigger/dds/event_loop.hpp"
#include "rigger/testing/domain.hpp"

namespace rigger::service {
namespace {

using dds::EventLoop;
using dds::Participant;

using namespace std::chrono_literals;

TEST(ServiceState, DirectorySeesReadyAndThenLeave) {
  testing::DomainLease domain;
  Participant observer(domain.id());
  EventLoop loop(observer);
  ServiceDirectory dir(observer);
  loop.on_data(dir.reader(), [&] { dir.update(); });

  Participant service(domain.id());
  auto announcer = std::make_unique<ServiceAnnouncer>(service, "svc-a", "echo");
  announcer->announce(ServiceStatus::kStarting);
  ASSERT_TRUE(loop.run_until([&] { return dir.services().count("svc-a") > 0; }, 5s));
  EXPECT_FALSE(dir.is_ready("svc-a"));
  announcer->announce(ServiceStatus::kReady, "all good");
  ASSERT_TRUE(loop.run_until([&] { return dir.is_ready("svc-a"); }, 5s));
  EXPECT_EQ(dir.services().at("svc-a").kind, "echo");
  EXPECT_EQ(dir.services().at("svc-a").detail, "all good");
  EXPECT_EQ(dir.ready_ids(), std::vector<std::string>{"svc-a"});

  announcer.reset();  // unregisters: seen at once, not after the lease
  ASSERT_TRUE(loop.run_until([&] { return !dir.services().at("svc-a").alive; }, 5s));
  EXPECT_FALSE(dir.is_ready("svc-a"));
}

TEST(ServiceState, SilentWriterIsLostAfterItsLease) {
  testing::DomainLease domain;
  Participant observer(domain.id());
  EventLoop loop(observer);
  ServiceDirectory dir(observer);
  loop.on_data(dir.reader(), [&] { dir.update(); });

  Participant service(domain.id());
  ServiceAnnouncer announcer(service, "svc-hung", "echo", 200ms);
  announcer.announce(ServiceStatus::kReady);
  ASSERT_TRUE(loop.run_until([&] { return dir.is_ready("svc-hung"); }, 5s));
  // Nobody asserts the service participant's liveliness any more (as with a hung work loop).
  const auto t0 = std::chrono::steady_clock::now();
  ASSERT_TRUE(loop.run_until([&] { return !dir.is_ready("svc-hung"); }, 3s));
  const auto lost_after = std::chrono::steady_clock::now() - t0;
  EXPECT_LT(lost_after, 1s) << "liveliness loss took "
                            << std::chrono::duration_cast<std::chrono::milliseconds>(lost_after).count() << " ms";
}

}  // namespace
}  // namespace rigger::service
