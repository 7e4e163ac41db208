#pragma once
/// @file
/// Running rigger's programs as a user does, from a shell, for the tests of the documented commands
/// (getting started, an installed tree): bash with a plain user's environment on the test's private DDS
/// domain, a timeout that kills the command and fails the test, and rigger-compose's service logs.

#include <signal.h>

#include <chrono>
#include <string>

#include <gtest/gtest.h>

#include "rigger/testing/cell.hpp"

namespace rigger::testing {

struct ShellResult {
  ExitStatus status;
  std::string output;
};

class ShellTest : public MultiProcessTest {
 protected:
  /// Runs `script` with bash; its output goes to <log dir>/<name>.out. After `timeout` it is killed and
  /// the test fails.
  ShellResult bash(const std::string& name, const std::string& script, std::chrono::milliseconds timeout) {
    ChildProcess p("/bin/bash", {"-c", script}, {}, cell_.log_dir() + "/" + name + ".out");
    auto st = p.wait(timeout);
    if (!st) {
      p.signal(SIGKILL);
      st = p.wait(std::chrono::seconds(5));
      ADD_FAILURE() << script << "\ndid not finish within " << timeout.count() << " ms\n" << p.log();
    }
    return {st.value_or(ExitStatus{}), p.log()};
  }

  /// `env` arguments for a user's plain shell on the test's domain: no CYCLONEDDS_URI (the programs find
  /// their DDS configuration themselves), RIGGER_DOMAIN the cell's private domain.
  /// Also a state folder of the test's own (world model database, controller journal; `state_dir`, by
  /// default in the test's log folder): in the default /var/tmp/rigger a world model waited more than 30 s
  /// on the lock of another test's cell, and the demo's bring-up failed.
  std::string plain_env(const std::string& state_dir = "") const {
    return "env -u CYCLONEDDS_URI RIGGER_DOMAIN=" + std::to_string(cell_.domain_id()) + " RIGGER_STATE_DIR='" +
           (state_dir.empty() ? cell_.log_dir() + "/state" : state_dir) + "'";
  }

  /// The last lines of every service's log in rigger-compose's log folder (the harness does not see it).
  std::string compose_logs() {
    const auto r = bash("compose-logs",
                        "for f in /tmp/rigger-compose/" + std::to_string(cell_.domain_id()) +
                            "/*.log; do echo \"===== $f\"; tail -n 25 \"$f\"; done",
                        std::chrono::seconds(30));
    return "\n" + r.output;
  }
};

}  // namespace rigger::testing
