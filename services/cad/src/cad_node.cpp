#include "cad_node.hpp"

#include "rigger/base/install.hpp"
#include "rigger/dds/conversions.hpp"

#include <chrono>

namespace rigger::cad_service {
CadServiceSettings read_settings(const Config& config) {
  CadServiceSettings settings;
  settings.cell_file = config_path(config, "cell_config", kDefaultCellFile);
  // An allowed folder that does not exist allows nothing (the shipped list names OpenCascade's samples,
  // which not every machine has): kept, not refused.
  for (const auto& dir : config.get<std::vector<std::string>>("allowed_dirs", {})) {
    settings.allowed_dirs.push_back(find_data_path(dir, config_file_of(config)).path);
  }
  settings.limits.max_bytes =
      static_cast<std::uintmax_t>(config.get_in_range<double>("max_file_mib", 64.0, 0.001, 1024.0) * (1 << 20));
  settings.limits.timeout = std::chrono::milliseconds(
      static_cast<long>(1000 * config.get_in_range<double>("read_timeout_s", 60.0, 0.1, 3600.0)));
  settings.max_models = static_cast<std::size_t>(config.get_in_range<int>("max_models", 16, 1, 1000));
  config.finish();
  return settings;
}

CadNode::CadNode(dds::ServiceContext& ctx, CadServiceSettings settings)
    : ctx_(ctx),
      service_(std::move(settings)),
      replies_(ctx.participant, protocol::cad::kReply),
      requests_(ctx.participant, protocol::cad::kRequest) {
  for (const auto& [object, status] : service_.object_status()) {
    ctx.log->info("object model object={} status={}", object, status);
  }
  ctx.loop.on_data(requests_, [this] { on_requests(); });
}

void CadNode::on_requests() {
  requests_.take([this](const rigger_cad_CadRequest& wire, const dds_sample_info_t&) {
    CadQuery query;
    const std::string client_id = dds::to_string(wire.client_id);
    query.model = dds::to_string(wire.model);
    query.args_json = dds::to_string(wire.args_json);
    if (wire.content._length > 0 && wire.content._buffer != nullptr) {
      query.content.assign(reinterpret_cast<const char*>(wire.content._buffer), wire.content._length);
    }
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
    reply.data._buffer = answer.data.data();
    reply.data._length = static_cast<std::uint32_t>(answer.data.size());
    reply.data._maximum = reply.data._length;
    reply.data._release = false;
    const dds_return_t rc = replies_.write(reply);
    if (rc != DDS_RETCODE_OK) {
      ctx_.log->error("reply write failed client={} request={} rc={}", client_id, wire.request_id, rc);
    }
  });
}

}  // namespace rigger::cad_service
