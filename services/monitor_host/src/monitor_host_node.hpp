#pragma once
/// @file
/// The monitor host's DDS node: an executor (rigger/skill/*) whose "skills" are the monitors of
/// monitor_registry. On START it builds the monitor, arms it with the START's params (bad params →
/// FAILURE BAD_PARAMS with every error), feeds it every rigger/robot/wrench sample (the sample time is
/// the wrench's header.stamp) and wakes it with an EventLoop timer at its next deadline (TIMEOUT,
/// SENSOR_STALE), never by polling. The moment it fires, the leaf reports FAILURE with the monitor's
/// code. SHUTDOWN → STOPPED at once (a monitor holds no device). A monitor never reports SUCCESS.
///
/// Configuration keys: monitor_host_settings() (rigger/monitor_host/settings.hpp).

#include <chrono>
#include <cstdint>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <utility>

#include "monitor.hpp"
#include "rigger/dds/pubsub.hpp"
#include "rigger/monitor_host/settings.hpp"
#include "rigger/protocol/robot.hpp"
#include "rigger/service/service.hpp"
#include "rigger/skill_protocol/executor_endpoint.hpp"

namespace rigger::monitor {

class MonitorHostNode : public service::Node {
 public:
  /// @throws ConfigError on bad configuration, DdsError.
  explicit MonitorHostNode(service::ServiceContext& ctx)
      : MonitorHostNode(ctx, read_settings(ctx.config, monitor_host_settings(ctx.options.id))) {}
  MonitorHostNode(service::ServiceContext& ctx, const MonitorHostSettings& settings);
  ~MonitorHostNode() override;

  /// Monitors armed now (for tests and logs).
  std::size_t active_monitors() const { return active_.size(); }

 private:
  using RunKey = std::pair<std::string, std::string>;  // (task_id, node_id)
  struct Active {
    skill_protocol::LeafRun run;
    std::string name;
    std::unique_ptr<Monitor> monitor;
    dds::EventLoop::TimerId timer = 0;  // 0: none pending
    std::optional<Stamp> timer_deadline;
  };

  void on_start(const skill_protocol::StartRequest& request);
  void on_shutdown(const skill_protocol::ShutdownRequest& request);
  void on_wrench();
  /// Reports FAILURE for `verdict` and forgets the run.
  void fire(const RunKey& key, const Verdict& verdict);
  /// Makes sure a timer is pending no later than the monitor's next deadline.
  void schedule(const RunKey& key, Active& active);
  void on_timer(const RunKey& key);
  void forget(const RunKey& key);

  service::ServiceContext& ctx_;
  std::size_t max_monitors_;
  dds::Reader<rigger_sensing_WrenchStamped> wrench_;
  std::map<RunKey, Active> active_;
  std::unique_ptr<skill_protocol::ExecutorEndpoint> endpoint_;  // last: its handlers use the members above
};

}  // namespace rigger::monitor
