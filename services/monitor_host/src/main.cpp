#include "monitor_host_node.hpp"

int main(int argc, char** argv) {
  return rigger::service::run_service(
      argc, argv,
      {"monitor_host",
       "Hosts TimerMonitor, ForceMonitor and YankMonitor leaves; a monitor never reports success.",
       {},
       [](rigger::service::ServiceContext& ctx) { return std::make_unique<rigger::monitor::MonitorHostNode>(ctx); }});
}
