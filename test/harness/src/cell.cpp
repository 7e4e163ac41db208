#include "rigger/testing/cell.hpp"

#include <signal.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <filesystem>
#include <iostream>
#include <mutex>
#include <set>
#include <sstream>

namespace rigger::testing {
namespace {

std::string current_test_name() {
  const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
  if (!info) return "no-test";
  std::string name = std::string(info->test_suite_name()) + "." + info->name();
  std::replace(name.begin(), name.end(), '/', '_');
  return name;
}

void make_dirs(const std::string& path) {
  std::string partial;
  std::stringstream ss(path);
  std::string part;
  while (std::getline(ss, part, '/')) {
    partial += part + "/";
    mkdir(partial.c_str(), 0777);
  }
}

/// Empties `dir` the first time this process uses it: a folder of that name left by an earlier run
/// (a test of the same name whose process had the same pid, as after a reboot) would otherwise show
/// that run's logs to this one. Cells of one test in one process share the folder, as before.
void claim_log_dir(const std::string& dir) {
  static std::mutex mutex;
  static std::set<std::string> claimed;
  std::lock_guard<std::mutex> lock(mutex);
  if (!claimed.insert(dir).second) return;
  std::error_code ignored;
  std::filesystem::remove_all(dir, ignored);
}

}  // namespace

Cell::Cell(const std::string& subfolder) {
  log_dir_ = std::string(RIGGER_BINARY_DIR) + "/test-logs/" + current_test_name() + "-" + std::to_string(getpid()) +
             (subfolder.empty() ? "" : "/" + subfolder);
  claim_log_dir(log_dir_);
  make_dirs(log_dir_);
  participant_ = std::make_unique<dds::Participant>(domain_.id());
  loop_ = std::make_unique<dds::EventLoop>(*participant_);
  directory_ = std::make_unique<service::ServiceDirectory>(*participant_);
  loop_->on_data(directory_->reader(), [this] { directory_->update(); });
}

Cell::~Cell() {
  stop_all(std::chrono::milliseconds(5000));
  processes_.clear();  // before the loop: the reapers post to it
}

ChildProcess& Cell::start(const std::string& name, const std::string& binary, std::vector<std::string> args,
                          bool add_domain, const std::map<std::string, std::string>& extra_env) {
  if (processes_.count(name)) throw std::invalid_argument("process name already used: " + name);
  if (add_domain) {
    args.push_back("--domain");
    args.push_back(std::to_string(domain_.id()));
  }
  std::map<std::string, std::string> env{{"RIGGER_DOMAIN", std::to_string(domain_.id())},
                                         {"CYCLONEDDS_URI", default_dds_config_uri()}};
  for (const auto& [key, value] : extra_env) env[key] = value;
  auto* loop = loop_.get();
  auto p = std::make_unique<ChildProcess>(binary, args, env, log_dir_ + "/" + name + ".log",
                                          [loop] { loop->post([] {}); });  // wake waiters on exit
  auto& ref = *p;
  processes_.emplace(name, std::move(p));
  return ref;
}

ChildProcess& Cell::process(const std::string& name) {
  auto it = processes_.find(name);
  if (it == processes_.end()) throw std::invalid_argument("no process named " + name);
  return *it->second;
}

bool Cell::wait_until(const std::function<bool()>& done, std::chrono::milliseconds timeout) {
  return loop_->run_until(done, timeout);
}

bool Cell::wait_ready(const std::vector<std::string>& service_ids, std::chrono::milliseconds timeout) {
  std::string died;
  const bool ok = loop_->run_until(
      [&] {
        for (auto& [name, p] : processes_) {
          if (!ended_.count(name) && !p->running()) {
            died = name;
            return true;
          }
        }
        return std::all_of(service_ids.begin(), service_ids.end(),
                           [&](const std::string& id) { return directory_->is_ready(id); });
      },
      timeout);
  if (!died.empty()) {
    ADD_FAILURE() << "process " << died << " ended before the cell was ready: "
                  << processes_.at(died)->wait(std::chrono::milliseconds(0))->describe();
    return false;
  }
  return ok;
}

std::optional<ExitStatus> Cell::stop(const std::string& name, int sig, std::chrono::milliseconds timeout) {
  auto& p = process(name);
  p.signal(sig);
  auto st = p.wait(timeout);
  if (st) ended_[name] = *st;
  return st;
}

StopReport Cell::stop_all(std::chrono::milliseconds timeout) {
  StopReport report;
  for (auto& [name, p] : processes_)
    if (!ended_.count(name)) p->signal(SIGINT);
  for (auto& [name, p] : processes_) {
    if (ended_.count(name)) continue;
    auto st = p->wait(timeout);
    if (!st) {
      report.ok = false;
      report.problems += name + ": did not stop within " + std::to_string(timeout.count()) + " ms after SIGINT\n";
      p->signal(SIGKILL);
      st = p->wait(std::chrono::milliseconds(5000));
    }
    if (st) {
      ended_[name] = *st;
      if (!st->ok()) {
        report.ok = false;
        report.problems += name + ": " + st->describe() + "\n";
      }
    }
  }
  return report;
}

std::string Cell::logs() const {
  std::string out;
  for (const auto& [name, p] : processes_) out += "----- " + name + " (" + p->log_path() + ")\n" + p->log() + "\n";
  return out;
}

void MultiProcessTest::TearDown() {
  const auto report = cell_.stop_all();
  if (expect_clean_exit_) {
    EXPECT_TRUE(report.ok) << report.problems;
  }
  if (HasFailure()) std::cerr << "===== logs of the cell's processes (domain " << cell_.domain_id() << ")\n" << cell_.logs();
}

std::unique_ptr<ChildProcess> start_riggerctl(Cell& cell, const std::string& name, const std::vector<std::string>& args) {
  std::vector<std::string> all = {"--domain", std::to_string(cell.domain_id())};
  all.insert(all.end(), args.begin(), args.end());
  dds::EventLoop* loop = &cell.loop();
  return std::make_unique<ChildProcess>(
      "riggerctl", all,
      std::map<std::string, std::string>{{"CYCLONEDDS_URI", default_dds_config_uri()},
                                         {"RIGGER_DOMAIN", std::to_string(cell.domain_id())}},
      cell.log_dir() + "/" + name + ".log", [loop] { loop->post([] {}); });
}

CtlResult run_riggerctl(Cell& cell, const std::string& name, const std::vector<std::string>& args,
                        std::chrono::milliseconds timeout) {
  auto p = start_riggerctl(cell, name, args);
  cell.wait_until([&] { return !p->running(); }, timeout);
  CtlResult r;
  r.status = p->wait(std::chrono::seconds(1));
  if (!r.status) p->signal(SIGKILL);
  r.output = p->log();
  return r;
}

}  // namespace rigger::testing
