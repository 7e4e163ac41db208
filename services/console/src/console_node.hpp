#pragma once
/// @file
/// The console's DDS node: reads task and node status, executor announcements, operator prompts and
/// the sensor streams for plots; asks the controller's journal, the world model and the CAD service;
/// writes recipes, task commands and operator responses on the same topics riggerctl uses. Its HTTP
/// side (HttpApi) runs on its own threads and reaches DDS only through the Backend below, which posts
/// each request to this node's event loop and waits for the loop's answer.
///
/// Configuration keys: console_settings() (rigger/console/settings.hpp).
#include <cstdint>
#include <future>
#include <map>
#include <memory>
#include <string>

#include <Eigen/Core>

#include "cell_feed.hpp"
#include "console_state.hpp"
#include "event_log.hpp"
#include "http_api.hpp"
#include "rehearsal_link.hpp"
#include "run_archive.hpp"
#include "rigger/dds/pubsub.hpp"
#include "rigger/idl/types.hpp"
#include "rigger/protocol/admittance.hpp"
#include "rigger/protocol/cad.hpp"
#include "rigger/protocol/crane.hpp"
#include "rigger/protocol/operator.hpp"
#include "rigger/protocol/robot.hpp"
#include "rigger/protocol/skill.hpp"
#include "rigger/protocol/task.hpp"
#include "rigger/protocol/world.hpp"
#include "rigger/service/service.hpp"
#include "rigger/world_client/world_client.hpp"
#include "task_feed.hpp"

namespace rigger::console {

class ConsoleNode : public service::Node, public Backend {
 public:
  /// @throws ConfigError (bad configuration, users file, port in use), DdsError.
  explicit ConsoleNode(service::ServiceContext& ctx);
  ~ConsoleNode() override;

  int port() const { return http_->port(); }

  // Backend (any thread but the loop's).
  ActionResult publish_recipe(const std::string& task_id, const std::string& recipe_json,
                              const std::string& submitter) override;
  ActionResult task_command(const std::string& task_id, const std::string& kind, const std::string& reason,
                            const std::string& issuer) override;
  ActionResult answer_prompt(const std::string& prompt_id, const std::string& answer, const std::string& operator_id,
                             const std::string& comment) override;
  ActionResult journal(const std::string& task_id) override;
  ActionResult world_entity(const std::string& id) override;
  ActionResult world_list() override;
  ActionResult cad(const std::string& kind, const std::string& model, const std::string& args_json) override;
  ActionResult cad_load(const std::string& name, std::string step, const std::string& args_json) override;
  ActionResult rehearse(const std::string& task_id, const std::string& recipe_json,
                        const std::string& submitter) override;
  ActionResult rehearsal_cell() override;
  ActionResult cell_request(const world_protocol::CellRequest& request) override;
  ActionResult cell_models(const std::string& sha256) override;

 private:
  /// Runs `work` on the loop; it must eventually set the promise it is given. Waits up to the query
  /// timeout (plus margin) for it.
  ActionResult on_loop(std::function<void(std::shared_ptr<std::promise<ActionResult>>)> work);
  void on_prompts();
  void on_journal_replies();
  void on_cad_replies();
  void on_cell_replies();
  void on_cell_models();
  /// A new revision of the cell: the pages are told (their parts and 3D views follow it).
  void on_cell_revisions();
  /// A sensor sample arrived: the plot timer runs while they do.
  void sampled();
  void plot_tick();
  /// Something moved: the cell timer runs while things do.
  void cell_moved();
  void cell_tick();

  service::ServiceContext& ctx_;
  std::chrono::milliseconds query_timeout_{3000};
  static constexpr std::chrono::milliseconds kCadLoadTimeout{120000};
  /// One CAD request (`content`: the STEP bytes of a LOAD, else empty), answered within `timeout`.
  ActionResult cad_request(rigger_cad_CadRequestKind kind, const std::string& model, const std::string& args_json,
                           std::string content, std::chrono::milliseconds timeout);
  EventLog events_;
  EventLog plots_;
  std::unique_ptr<RunArchive> runs_;  ///< null: runs are not kept
  ConsoleState state_;
  SkillCatalog skills_;

  TaskFeed tasks_;
  dds::Reader<rigger_operator_ui_OperatorPrompt> prompts_;
  dds::Reader<rigger_sensing_WrenchStamped> wrench_;
  dds::Reader<rigger_crane_CraneState> crane_;
  dds::Reader<rigger_robot_RobotState> robot_;
  dds::Reader<rigger_admittance_AdmittanceState> admittance_;
  dds::Reader<rigger_world_EntityState> entities_;
  dds::Writer<rigger_world_CellRequest> cell_requests_;
  dds::Reader<rigger_world_CellReply> cell_replies_;
  dds::Reader<rigger_world_CellRevision> cell_revisions_;
  /// The STEP models the cell's running revision pins (rigger/world/cell_model), for the rehearsal cell.
  dds::Reader<rigger_world_CellModel> cell_models_;
  std::map<std::string, world_protocol::CellModel> models_by_sha_;
  dds::Writer<rigger_task_Recipe> recipes_;
  dds::Writer<rigger_task_TaskCommand> task_commands_;
  dds::Writer<rigger_operator_ui_OperatorResponse> responses_;
  dds::Writer<rigger_task_JournalQuery> journal_queries_;
  dds::Reader<rigger_task_JournalReply> journal_replies_;
  dds::Writer<rigger_cad_CadRequest> cad_requests_;
  dds::Reader<rigger_cad_CadReply> cad_replies_;
  std::unique_ptr<world_client::WorldClient> world_;
  std::unique_ptr<RehearsalLink> rehearsal_;  ///< none without rehearsal_domain

  std::string client_id_;
  std::uint64_t next_request_ = 1;
  std::uint64_t command_seq_ = 1;
  struct PendingQuery {
    std::shared_ptr<std::promise<ActionResult>> promise;
    dds::EventLoop::TimerId timer = 0;
  };
  std::map<std::uint64_t, PendingQuery> journal_pending_;
  std::map<std::uint64_t, PendingQuery> cad_pending_;
  std::map<std::uint64_t, PendingQuery> cell_pending_;

  // Plots: the latest sample of each stream, decimated by plot_tick().
  Eigen::Vector3d force_sum_ = Eigen::Vector3d::Zero();
  int force_count_ = 0;
  double last_force_norm_ = -1.0;
  double last_tick_s_ = 0.0;
  Eigen::Vector3d crane_velocity_ = Eigen::Vector3d::Zero();
  Eigen::Vector3d robot_velocity_ = Eigen::Vector3d::Zero();
  double servo_error_m_ = 0.0, servo_error_rad_ = 0.0;
  bool have_crane_ = false, have_robot_ = false, have_admittance_ = false, fresh_ = false;
  std::chrono::nanoseconds plot_period_{50000000};
  dds::EventLoop::TimerId plot_timer_ = 0;  ///< 0: stopped (no sample since the last tick)

  // The pages' 3D cell: where things are, sent at most kCellRateHz times a second.
  CellFeed cell_;
  dds::EventLoop::TimerId cell_timer_ = 0;  ///< 0: stopped (nothing moved since the last tick)

  std::unique_ptr<HttpApi> http_;  // last: its threads stop first
};

}  // namespace rigger::console
