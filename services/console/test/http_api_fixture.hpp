#pragma once
// The console's HTTP side over real loopback HTTP (cpp-httplib's client), with a recording Backend in
// place of DDS: the fixture its tests share (http_api_test.cpp, http_api_limits_test.cpp).
#include <httplib.h>

#include <unistd.h>

#include <atomic>
#include <filesystem>
#include <functional>
#include <fstream>
#include <thread>
#include <mutex>

#include <gtest/gtest.h>

#include "http_api.hpp"
#include "rigger/base/logging.hpp"


namespace rigger::console::testing {

using nlohmann::json;
using namespace std::chrono_literals;

/// Records what the HTTP side asked for; answers ok.
class RecordingBackend : public Backend {
 public:
  ActionResult publish_recipe(const std::string& task_id, const std::string&, const std::string& submitter) override {
    return record("publish " + task_id + " by " + submitter);
  }
  ActionResult task_command(const std::string& task_id, const std::string& kind, const std::string&,
                            const std::string& issuer) override {
    return record(kind + " " + task_id + " by " + issuer);
  }
  ActionResult answer_prompt(const std::string& prompt_id, const std::string& answer, const std::string& who,
                             const std::string&) override {
    return record("answer " + prompt_id + " " + answer + " by " + who);
  }
  ActionResult journal(const std::string&) override { return {true, "", json::array()}; }
  ActionResult world_entity(const std::string&) override { return world_answer_; }
  ActionResult world_list() override { return world_answer_; }
  ActionResult world_answer_{false, "no world model", {}};
  ActionResult cad(const std::string& kind, const std::string& model, const std::string& args) override {
    std::lock_guard lock(mutex_);
    cad_requests_.push_back(kind + " " + model + " " + args);
    return cad_answer_;
  }
  std::vector<std::string> cad_requests() {
    std::lock_guard lock(mutex_);
    return cad_requests_;
  }
  ActionResult cad_answer_{false, "no CAD service on this domain", {}};
  ActionResult cad_load(const std::string& name, std::string step, const std::string& args_json) override {
    std::lock_guard lock(mutex_);
    cad_requests_.push_back("load " + name + " " + std::to_string(step.size()) + " bytes" +
                            (args_json == "{}" ? "" : " " + args_json));
    return cad_answer_;
  }
  ActionResult rehearsal_cell() override { return {true, "", {{"phase", "starting"}, {"log", "/tmp/cell.log"}}}; }
  ActionResult rehearse(const std::string& task_id, const std::string&, const std::string& submitter) override {
    if (!rehearse_answer_.ok) return rehearse_answer_;
    record("rehearse " + task_id + " by " + submitter);
    return rehearse_answer_;
  }
  ActionResult rehearse_answer_{true, "", {}};
  /// The cell's models (rigger/world/cell_model), by sha256.
  ActionResult cell_models(const std::string& sha256) override {
    std::lock_guard lock(mutex_);
    if (sha256.empty()) {
      json list = json::array();
      for (const auto& [sha, m] : cell_models_) list.push_back({{"name", m.name}, {"sha256", sha}, {"bytes", m.step.size()}});
      return {true, "", list};
    }
    const auto it = cell_models_.find(sha256);
    if (it == cell_models_.end()) return {false, "the cell's running revision pins no model of sha256 " + sha256, {}};
    return {true, "", {{"name", it->second.name}, {"sha256", sha256}, {"step", it->second.step}}};
  }
  std::map<std::string, world_protocol::CellModel> cell_models_;
  ActionResult cell_request(const world_protocol::CellRequest& q) override {
    const std::string op(world_protocol::to_string(*q.op));
    record("cell " + op + (q.dry_run ? " dry" : "") + (q.revision ? " " + std::to_string(q.revision) : "") + " by " + q.who +
           (q.cell_json.empty() ? "" : " " + q.cell_json));
    std::lock_guard lock(mutex_);
    return q.dry_run ? cell_check_ : cell_answer_;
  }
  // As the world model answers (cell_keeper.cpp): the diff is the result's "changes", beside its summary.
  ActionResult cell_check_{true,
                           "",
                           {{"code", "ACCEPTED"},
                            {"cell_revision", 1},
                            {"result", {{"summary", "moved part"}, {"changes", {{"moved", {{{"id", "part"}}}}}}}}}};
  ActionResult cell_answer_{true,
                            "",
                            {{"code", "ACCEPTED"},
                             {"cell_revision", 2},
                             {"result", {{"summary", "moved part"}, {"changes", {{"moved", {{{"id", "part"}}}}}}}}}};
  std::vector<std::string> cad_requests_;
  std::vector<std::string> actions() {
    std::lock_guard lock(mutex_);
    return actions_;
  }

 private:
  ActionResult record(std::string what) {
    std::lock_guard lock(mutex_);
    actions_.push_back(std::move(what));
    return {true, "", {}};
  }
  std::mutex mutex_;
  std::vector<std::string> actions_;
};

class HttpApiTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = ::testing::TempDir() + "/console-http-" + std::to_string(::getpid());
    created_ = make_users(dir_ + "/users.json", {{"ada", Role::kProgrammer}, {"olu", Role::kOperator}, {"vic", Role::kViewer}});
    std::filesystem::create_directories(dir_ + "/web");
    HttpConfig config;
    config.port = 0;
    config.web_dir = dir_ + "/web";
    config.audit_log = dir_ + "/audit.log";
    config.confirm_timeout = 300ms;
    config.max_body_bytes = 64 * 1024;
    configure(config);
    runs_ = std::make_unique<RunArchive>(dir_ + "/runs", RunArchive::Limits{});
    api_ = std::make_unique<HttpApi>(config, Users::load(dir_ + "/users.json"), state_, events_, plots_, backend_,
                                     skills_, null_logger(), rehearsal(), runs_.get());
    api_->start();
    client_ = std::make_unique<httplib::Client>("127.0.0.1", api_->port());
  }
  /// The configuration's changes of a derived fixture.
  virtual void configure(HttpConfig&) {}
  /// The rehearsal cell's side the HTTP side gets (none here).
  virtual std::optional<RehearsalFeed> rehearsal() { return std::nullopt; }
  void TearDown() override {
    api_->stop();
    std::filesystem::remove_all(dir_);
  }
  httplib::Headers as(int user) const { return {{"Authorization", "Bearer " + created_[user].token}}; }
  httplib::Result post(const std::string& path, const std::string& body, int user = -1) {
    return user < 0 ? client_->Post(path.c_str(), body, "application/json")
                    : client_->Post(path.c_str(), as(user), body, "application/json");
  }
  static json body(const httplib::Result& r) { return json::parse(r->body); }

  std::string dir_;
  std::vector<CreatedUser> created_;
  EventLog events_{1000, "42"};
  EventLog plots_{100, "42"};
  ConsoleState state_{events_};
  RecordingBackend backend_;
  SkillCatalog skills_;
  std::unique_ptr<RunArchive> runs_;
  std::unique_ptr<HttpApi> api_;
  std::unique_ptr<httplib::Client> client_;
};

constexpr int kAda = 0, kOlu = 1, kVic = 2;

}  // namespace rigger::console::testing
