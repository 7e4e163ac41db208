// rigger-compose config: the compose file validated and shown resolved, in start order.
#include <unistd.h>

#include <cstdio>

#include "command_support.hpp"
#include "rigger/compose/process_util.hpp"
#include "rigger/compose/start_order.hpp"

namespace rigger::compose::cli {

int config(const GlobalOptions& g) {
  const ComposeFile file = load(g);
  const auto hosts = this_host_names(host_option(g));
  std::vector<ServiceDeps> graph;
  for (const auto& s : file.services) graph.push_back({s.name, s.depends_on});
  std::printf("file     %s\nroot     %s\ndomain   %u\ndds      %s\nlog_dir  %s\nbin_dir  %s\n", file.path.c_str(),
              file.root.c_str(), file.domain, file.dds_config.empty() ? "(CYCLONEDDS_URI)" : file.dds_config.c_str(),
              file.log_dir.c_str(), file.bin_dir.c_str());
  std::printf("services in start order:\n");
  bool any_remote = false;
  for (const auto& name : start_order(graph)) {
    const auto& s = *file.find(name);
    const bool built = access(s.binary.c_str(), X_OK) == 0;
    any_remote = any_remote || !is_local_host(s.host, hosts);
    std::string deps;
    for (const auto& d : s.depends_on) deps += (deps.empty() ? "" : ",") + d;
    std::printf("  %-20s host=%-12s restart=%-10s %s%s%s%s\n", name.c_str(),
                (s.host + (is_local_host(s.host, hosts) ? "" : "*")).c_str(), to_string(s.restart),
                file.display_path(s.binary).c_str(), built ? "" : " (not built)",
                s.config.empty() ? "" : (" --config " + file.display_path(s.config)).c_str(),
                deps.empty() ? "" : ("  after " + deps).c_str());
  }
  if (any_remote) std::printf("(* another host: started there, from the same file)\n");
  return kExitOk;
}

}  // namespace rigger::compose::cli
