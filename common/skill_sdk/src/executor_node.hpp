#pragma once
/// @file
/// The skill executor's DDS node: announces the skills its configuration names (ExecutorEndpoint),
/// runs one SkillRun per START, turns SHUTDOWN into the running skill's safe stop, and reports the
/// run's PROGRESS and its end (SUCCESS, FAILURE, or STOPPED once the safe stop is reached).
///
/// Configuration keys: executor_settings() (rigger/skill_sdk/executor_settings.hpp).
/// On node destruction (service stop) every running skill's safe stop is commanded (not awaited: the
/// loop has stopped).

#include <map>
#include <memory>
#include <string>
#include <utility>

#include "dds_cell_devices.hpp"
#include "dds_devices.hpp"
#include "rigger/service/service.hpp"
#include "rigger/skill_protocol/executor_endpoint.hpp"
#include "rigger/skill_sdk/executor_settings.hpp"
#include "rigger/skill_sdk/skill_registry.hpp"
#include "rigger/skill_sdk/skill_run.hpp"
#include "rigger/world_client/world_client.hpp"
#include "world_resolver.hpp"

namespace rigger::skill_sdk {

/// Timers on a dds::EventLoop.
class LoopTimers final : public Timers {
 public:
  explicit LoopTimers(dds::EventLoop& loop) : loop_(loop) {}
  std::uint64_t after(std::chrono::nanoseconds delay, std::function<void()> handler) override {
    return loop_.after(delay, std::move(handler));
  }
  void cancel(std::uint64_t id) override { loop_.cancel(id); }

 private:
  dds::EventLoop& loop_;
};

class SkillExecutorNode : public service::Node {
 public:
  /// @throws ConfigError, DdsError.
  SkillExecutorNode(service::ServiceContext& ctx, SkillRegistry registry);
  ~SkillExecutorNode() override;

 private:
  using RunKey = std::pair<std::string, std::string>;
  void on_start(const skill_protocol::StartRequest& request);
  void on_shutdown(const skill_protocol::ShutdownRequest& request);
  skill_protocol::PauseAnswer on_pause(const skill_protocol::PauseRequest& request);

  service::ServiceContext& ctx_;
  SkillRegistry registry_;
  LoopTimers timers_;
  std::unique_ptr<DdsRobot> robot_;
  std::unique_ptr<DdsGripper> gripper_;
  std::unique_ptr<world_client::WorldClient> world_client_;
  std::unique_ptr<WorldFeatureResolver> resolver_;
  std::unique_ptr<DdsWorldAccess> world_access_;
  std::unique_ptr<DdsCraneMonitor> crane_;
  std::unique_ptr<DdsVisionTracker> tracker_;
  std::unique_ptr<DdsAdmittanceController> admittance_;
  std::unique_ptr<DdsOperatorPanel> operator_panel_;
  Devices devices_;
  SkillRun::Options run_options_;
  std::map<RunKey, std::unique_ptr<SkillRun>> runs_;
  std::unique_ptr<skill_protocol::ExecutorEndpoint> endpoint_;  // last: its handlers use the members above
};

}  // namespace rigger::skill_sdk
