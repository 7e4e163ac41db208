#pragma once
/// @file
/// A lab of hosts made by deploy/lab-hosts for a test (docs/deploy.md, "Trying it on one machine"):
/// network namespaces `<lab>-<host>`, each with one interface eth0 on the lab's bridge, so that rigger's
/// processes and a peer meet across real interfaces with multicast discovery. Needs root.
///
///   Lab lab("r" + std::to_string(getpid() % 10000000), {"rigger", "ros2"});
///   lab.enter("rigger");   // this thread's sockets, threads and children live on host rigger now
///   cell.start("peer", RIGGER_SOURCE_DIR "/deploy/lab-hosts", {"exec", "ros2", …}, true, lab.env());
///
/// The lab is torn down however the test ends: the destructor does it when the test returns or fails,
/// and a watcher process started with the lab does it when the test process dies without returning
/// (a crash, SIGKILL by ctest's timeout), because it waits on a pipe only the test process holds open.

#include <sys/types.h>

#include <map>
#include <string>
#include <vector>

namespace rigger::testing {

class Lab {
 public:
  /// `deploy/lab-hosts up hosts…` with RIGGER_LAB=`name` (1-8 lower-case letters or digits), after
  /// deleting any left-over lab of that name. @throws std::runtime_error with lab-hosts' output when the
  /// lab cannot be made.
  Lab(std::string name, const std::vector<std::string>& hosts);
  Lab(const Lab&) = delete;
  Lab& operator=(const Lab&) = delete;
  /// Leaves the host entered, kills (by PID) what still runs in the lab's namespaces, deletes them.
  ~Lab();

  const std::string& name() const { return name_; }
  /// eth0's IPv4 address of `host` (e.g. "10.213.0.2"). @throws std::out_of_range for an unknown host.
  const std::string& address(const std::string& host) const { return addresses_.at(host); }
  /// The environment a `deploy/lab-hosts` command for this lab needs: RIGGER_LAB.
  std::map<std::string, std::string> env() const { return {{"RIGGER_LAB", name_}}; }
  /// Moves the calling thread into `host`'s network namespace: sockets it opens, threads it starts
  /// and processes it spawns from now on live there. @throws std::runtime_error when setns fails.
  void enter(const std::string& host);
  /// Back to the namespace the lab was made from (nothing when no host was entered).
  void leave();
  /// The result of the teardown so far: empty when it went well, else what failed.
  const std::string& teardown_problems() const { return teardown_problems_; }
  /// Tears the lab down now (the destructor does it otherwise). Returns teardown_problems().
  const std::string& tear_down();

 private:
  std::string name_;
  std::map<std::string, std::string> addresses_;
  int origin_ns_ = -1;   ///< the namespace to return to, while a host is entered
  int watcher_fd_ = -1;  ///< write end of the watcher's pipe; closing it (or dying) wakes the watcher
  bool torn_down_ = false;
  std::string teardown_problems_;
};

}  // namespace rigger::testing
