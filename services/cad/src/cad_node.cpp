#include "cad_node.hpp"

#include "rigger/base/install.hpp"
#include "rigger/dds/conversions.hpp"
#include "rigger/dds/sequences.hpp"

#include <chrono>

namespace rigger::cad_service {
const SettingsTable<CadServiceSettings>& cad_settings() {
  using S = CadServiceSettings;
  static const SettingsTable<S> table{
      path_setting<S>("cell_config", kDefaultCellFile, &S::cell_file,
                      "the cell file: relative to this file, then to the data folder; its objects' STEP models are "
                      "loaded at start"),
      // A missing folder is kept, not refused: the shipped list names OpenCascade's samples, which not
      // every machine has.
      setting<S>(
          "allowed_dirs", std::vector<std::string>{},
          [](S& s, const std::vector<std::string>& dirs, const Config& config) {
            for (const auto& dir : dirs) s.allowed_dirs.push_back(find_data_path(dir, config_file_of(config)).path);
          },
          "folders a request may name files in (besides the cell's models), each relative to this file, then "
          "to the data folder; a folder that does not exist allows nothing"),
      setting<S>("max_file_mib", 64.0, {0.001, 1024.0},
                 [](S& s, double mib) { s.limits.max_bytes = static_cast<std::uintmax_t>(mib * (1 << 20)); },
                 "larger STEP files are refused before parsing"),
      setting<S>("read_timeout_s", 60.0, {0.1, 3600.0},
                 [](S& s, double v) { s.limits.timeout = std::chrono::milliseconds(static_cast<long>(1000 * v)); },
                 "wall time of the reader child process (killed after)"),
      setting<S>("max_models", 16, {1, 1000}, &S::max_models,
                 "models kept besides the cell's objects' (the oldest is dropped first)"),
  };
  return table;
}

CadServiceSettings read_settings(const Config& config) { return rigger::read_settings(config, cad_settings()); }

CadNode::CadNode(service::ServiceContext& ctx, CadServiceSettings settings)
    : ctx_(ctx),
      service_(std::move(settings)),
      replies_(ctx.participant, protocol::cad::kReply),
      requests_(ctx.participant, protocol::cad::kRequest),
      follower_(ctx.participant, ctx.loop, ctx.log, service_.cell_file(),
                [this](const cell_follower::FollowedRevision& revision) { return on_revision(revision); },
                &ctx.announcer) {
  log_objects();
  ctx.loop.on_data(requests_, [this] { on_requests(); });
}

void CadNode::log_objects() const {
  for (const auto& [object, status] : service_.object_status()) {
    ctx_.log->info("object model object={} status={}", object, status);
  }
}

cell_follower::Outcome CadNode::on_revision(const cell_follower::FollowedRevision& revision) {
  service_.follow(revision.cell, revision.model_dir);
  ctx_.log->info("cell revision {}: {} object models", revision.revision, service_.object_status().size());
  log_objects();
  return cell_follower::Outcome::take();
}

void CadNode::on_requests() {
  requests_.take([this](const rigger_cad_CadRequest& wire, const dds_sample_info_t&) {
    CadQuery query;
    const std::string client_id = dds::to_string(wire.client_id);
    query.model = dds::to_string(wire.model);
    query.args_json = dds::to_string(wire.args_json);
    const auto content = dds::elements(wire.content);
    query.content.assign(reinterpret_cast<const char*>(content.data()), content.size());
    CadAnswer answer;
    switch (wire.kind) {
      case rigger_cad_CAD_LOAD: query.kind = QueryKind::kLoad; break;
      case rigger_cad_CAD_FEATURES: query.kind = QueryKind::kFeatures; break;
      case rigger_cad_CAD_TESSELLATION: query.kind = QueryKind::kTessellation; break;
      case rigger_cad_CAD_FRAME: query.kind = QueryKind::kFrame; break;
      case rigger_cad_CAD_DERIVE: query.kind = QueryKind::kDerive; break;
      default:
        answer.code = "CAD_BAD_REQUEST";
        answer.message = "unknown request kind " + std::to_string(static_cast<int>(wire.kind));
    }
    const auto started = std::chrono::steady_clock::now();
    if (answer.code.empty()) {
      answer = service_.answer(query);
    }
    const auto ms = std::chrono::duration_cast<std::chrono::milliseconds>(std::chrono::steady_clock::now() - started).count();
    if (answer.ok) {
      ctx_.log->info("answered client={} request={} kind={} model={} ms={}", client_id, wire.request_id,
                     static_cast<int>(wire.kind), answer.model_sha256.substr(0, 12), ms);
    } else {
      ctx_.log->warn("refused client={} request={} code={} reason={}", client_id, wire.request_id, answer.code,
                     answer.message);
    }
    rigger_cad_CadReply reply{};
    reply.client_id = dds::wire_string(client_id);
    reply.request_id = wire.request_id;
    reply.ok = answer.ok;
    reply.code = dds::wire_string(answer.code);
    reply.message = dds::wire_string(answer.message);
    reply.model_sha256 = dds::wire_string(answer.model_sha256);
    reply.result_json = dds::wire_string(answer.result_json);
    dds::wire_sequence(reply.data, answer.data);
    const dds_return_t rc = replies_.write(reply);
    if (rc != DDS_RETCODE_OK) {
      ctx_.log->error("reply write failed client={} request={} rc={}", client_id, wire.request_id, rc);
    }
  });
}

}  // namespace rigger::cad_service
