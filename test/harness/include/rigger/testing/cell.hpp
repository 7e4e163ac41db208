#pragma once
/// @file
/// A set of real rigger processes on a private DDS domain, for multi-process tests:
///
///   rigger::testing::Cell cell;                       // own domain id, own log folder
///   cell.start("echo-1", "echo", {"--id", "echo-1"});  // binary from the build's bin/
///   ASSERT_TRUE(cell.wait_ready({"echo-1"}, 5s));      // waits on READY announcements, never sleeps
///   ...                                                // drive it through cell.participant()
///   EXPECT_TRUE(cell.stop_all().ok);                   // SIGINT, wait, check exit codes
///
/// The MultiProcessTest fixture does the last step in TearDown and prints every log on failure.

#include <chrono>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "rigger/dds/event_loop.hpp"
#include "rigger/dds/participant.hpp"
#include "rigger/service/service_state.hpp"
#include "rigger/testing/domain.hpp"
#include "rigger/testing/process.hpp"

namespace rigger::testing {

struct StopReport {
  bool ok = true;          ///< every process exited with code 0 after SIGINT
  std::string problems;    ///< one line per process that did not
};

class Cell {
 public:
  /// `subfolder`: a second cell of the same test (another domain) keeps its logs and files in that
  /// subfolder of the test's log folder, so that processes of the same name do not share a log.
  explicit Cell(const std::string& subfolder = "");
  ~Cell();

  std::uint32_t domain_id() const { return domain_.id(); }
  dds::Participant& participant() { return *participant_; }
  dds::EventLoop& loop() { return *loop_; }
  service::ServiceDirectory& directory() { return *directory_; }
  const std::string& log_dir() const { return log_dir_; }

  /// Starts `binary` (a name in the build's bin/ or a path) as process `name` with `--domain <id>`
  /// appended unless `add_domain` is false. `env` adds to (or replaces) the variables the cell sets:
  /// RIGGER_DOMAIN and CYCLONEDDS_URI.
  ChildProcess& start(const std::string& name, const std::string& binary, std::vector<std::string> args = {},
                      bool add_domain = true, const std::map<std::string, std::string>& env = {});
  ChildProcess& process(const std::string& name);
  bool has(const std::string& name) const { return processes_.count(name) > 0; }

  /// Runs the test's event loop (its readers and timers) until every id in `service_ids` announced
  /// READY and is alive, or `timeout`. Fails fast if one of the started processes exits meanwhile.
  bool wait_ready(const std::vector<std::string>& service_ids, std::chrono::milliseconds timeout);
  /// Runs the test's event loop until `done()` or `timeout`.
  bool wait_until(const std::function<bool()>& done, std::chrono::milliseconds timeout);

  /// Sends `sig` to process `name` and waits for it to end.
  std::optional<ExitStatus> stop(const std::string& name, int sig, std::chrono::milliseconds timeout);
  /// SIGINT to every running process; each must exit 0 within `timeout`.
  StopReport stop_all(std::chrono::milliseconds timeout = std::chrono::milliseconds(10000));
  /// Every process's log, headed by its name.
  std::string logs() const;

 private:
  DomainLease domain_;
  std::string log_dir_;
  std::unique_ptr<dds::Participant> participant_;
  std::unique_ptr<dds::EventLoop> loop_;
  std::unique_ptr<service::ServiceDirectory> directory_;
  std::map<std::string, std::unique_ptr<ChildProcess>> processes_;
  std::map<std::string, ExitStatus> ended_;
};

/// Starts `riggerctl --domain <the cell's> args...` as a client, not one of the cell's services (any exit
/// code may be the expected one): its output goes to <log dir>/<name>.log, and its end wakes the cell's
/// loop, so `cell.wait_until([&] { return !p->running(); }, …)` returns at once.
std::unique_ptr<ChildProcess> start_riggerctl(Cell& cell, const std::string& name, const std::vector<std::string>& args);

/// How a riggerctl run ended.
struct CtlResult {
  std::optional<ExitStatus> status;  ///< none: it had not ended by the timeout (it was killed)
  std::string output;                ///< its stdout and stderr
  int code() const { return status && status->exited ? status->code : -1; }
};

/// Runs riggerctl as start_riggerctl() does, to its end, the cell's loop running meanwhile (so the test's
/// readers keep up); one still running after `timeout` is killed and its result has no status.
CtlResult run_riggerctl(Cell& cell, const std::string& name, const std::vector<std::string>& args,
                        std::chrono::milliseconds timeout = std::chrono::seconds(30));

/// GoogleTest fixture owning a Cell: stops every process in TearDown, expects clean exits, and prints
/// the logs of all processes when the test failed.
class MultiProcessTest : public ::testing::Test {
 protected:
  void TearDown() override;
  Cell cell_;
  /// Set to false in tests that end processes on purpose with unclean exits.
  bool expect_clean_exit_ = true;
};

}  // namespace rigger::testing
