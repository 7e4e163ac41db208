// STEP models that travel with a cell revision over DDS: a part whose STEP file exists only on the
// applying side (a laptop's folder) is sent with `riggerctl cell apply --with-models`, pinned by its
// sha256; the real world model keeps it, and the real CAD service and cell_sim, each on a cell folder of
// their own that lacks it, take it from rigger/world/cell_model: the CAD service answers the part's
// features and the physics holds the part where the revision put it. Without the models the revision is
// refused and nothing changes; a restarted world model runs the revision again from its own store.
#include <signal.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <optional>
#include <string>

#include <gtest/gtest.h>
#include <Eigen/Geometry>
#include <nlohmann/json.hpp>

#include "cell_revision_support.hpp"
#include "cell_sim_test_support.hpp"
#include "rigger/base/sha256.hpp"
#include "rigger/cad/model.hpp"
#include "rigger/cad/parts.hpp"
#include "rigger/dds/conversions.hpp"
#include "rigger/dds/pubsub.hpp"
#include "rigger/dds/qos.hpp"
#include "rigger/protocol/cad.hpp"
#include "rigger/protocol/sim.hpp"
#include "rigger/protocol/world.hpp"
#include "rigger/testing/cell.hpp"
#include "rigger/world_protocol/cell_protocol.hpp"

namespace rigger::testing {
namespace {

using namespace std::chrono_literals;
namespace fs = std::filesystem;
using json = nlohmann::json;

std::string read_bytes(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

class CellModelTransportTest : public MultiProcessTest {
 protected:
  CellModelTransportTest() {
    // Each process on a copy of the shipped cell folder of its own; the laptop's copy also has the plate.
    for (const char* who : {"world", "sim", "cad", "laptop"}) {
      const fs::path folder = fs::path(cell_.log_dir()) / who;
      fs::create_directories(folder);
      fs::copy(repo_file("deploy/cell/simulated_cell.json"), folder / "cell.json");
      fs::copy(repo_file("deploy/cell/models"), folder / "models", fs::copy_options::recursive);
    }
    laptop_ = fs::path(cell_.log_dir()) / "laptop";
    fs::create_directories(laptop_ / "imported");
    cad::write_step(cad::parts::plate(), "plate", laptop_ / "imported/plate.step");
    plate_sha256_ = sha256_hex(read_bytes(laptop_ / "imported/plate.step"));

    cell_.loop().on_data(models_, [this] {
      models_.take([this](const rigger_world_CellModel& wire, const dds_sample_info_t&) {
        ++models_seen_[dds::to_string(wire.sha256)];
      });
    });
    cell_.loop().on_data(truths_, [this] {
      truths_.take([this](const rigger_vision_TrackedPose& p, const dds_sample_info_t&) {
        truth_[dds::to_string(p.object_id)] = dds::to_domain(p.pose.pose);
      });
    });
    cell_.loop().on_data(cad_replies_, [this] {
      cad_replies_.take([this](const rigger_cad_CadReply& r, const dds_sample_info_t&) {
        if (dds::to_string(r.client_id) == "transport-test")
          cad_answers_[r.request_id] = {r.ok, dds::to_string(r.code) + ": " + dds::to_string(r.message),
                                        dds::to_string(r.model_sha256), dds::to_string(r.result_json)};
      });
    });
  }

  /// deploy/config/<name>.json with its cell file `key` set to `who`'s copy and `patch` merged; its path.
  std::string config(const std::string& name, const char* key, const std::string& who, json patch = json::object()) {
    std::ifstream in(repo_file("deploy/config/" + name + ".json"));
    json c = json::parse(in);
    c[key] = (fs::path(cell_.log_dir()) / who / "cell.json").string();
    c.merge_patch(patch);
    const std::string path = cell_.log_dir() + "/" + name + ".json";
    std::ofstream(path) << c.dump(2);
    return path;
  }

  void start_world_model(const std::string& name = "world_model") {
    cell_.start(name, "world_model",
                {"--config", config("world_model", "cell_config", "world"), "--db", cell_.log_dir() + "/world.sqlite"});
  }

  struct CadAnswer {
    bool ok = false;
    std::string why, sha256, result_json;
  };

  CadAnswer cad_call(rigger_cad_CadRequestKind kind, const std::string& model) {
    const std::uint64_t id = ++cad_id_;
    rigger_cad_CadRequest request{};
    request.client_id = const_cast<char*>("transport-test");
    request.request_id = id;
    request.kind = kind;
    request.model = dds::wire_string(model);
    request.args_json = const_cast<char*>("");
    EXPECT_EQ(cad_requests_.write(request), DDS_RETCODE_OK);
    EXPECT_TRUE(cell_.wait_until([&] { return cad_answers_.count(id) > 0; }, 30s)) << "no CAD answer to " << id;
    return cad_answers_[id];
  }

  fs::path laptop_;
  std::string plate_sha256_;
  dds::Reader<rigger_world_CellModel> models_{cell_.participant(), protocol::world::kCellModel};
  std::map<std::string, int> models_seen_;
  dds::Reader<rigger_vision_TrackedPose> truths_{cell_.participant(), protocol::sim::kGroundTruth,
                                                 dds::qos::sensor_stream().keep_last(64)};
  std::map<std::string, Eigen::Isometry3d> truth_;
  dds::Writer<rigger_cad_CadRequest> cad_requests_{cell_.participant(), protocol::cad::kRequest};
  dds::Reader<rigger_cad_CadReply> cad_replies_{cell_.participant(), protocol::cad::kReply};
  std::map<std::uint64_t, CadAnswer> cad_answers_;
  std::uint64_t cad_id_ = 0;
};

TEST_F(CellModelTransportTest, APartOnlyTheApplyingSideHasReachesTheWorldModelTheCadServiceAndThePhysics) {
  const std::string port = std::to_string(free_tcp_port());
  cell_.start("cell_sim", "cell_sim", {"--config", config("cell_sim", "cell_file", "sim"), "--plc-port", port});
  start_world_model();
  cell_.start("cad", "cad", {"--id", "cad", "--config", config("cad", "cell_config", "cad")});
  ASSERT_TRUE(cell_.wait_ready({"cell_sim", "world_model", "cad"}, 60s)) << cell_.logs();
  ASSERT_TRUE(service_detail_says(cell_, "cell_sim", "cell revision 1")) << cell_.logs();

  // The laptop's cell: the plate, static on the floor beside the cell, its model in the laptop's folder only.
  json doc = json::parse(read_bytes(laptop_ / "cell.json"));
  const Eigen::Vector3d at(4.5, 0.8, 0.0);
  doc["entities"].push_back({{"id", "plate"},
                             {"kind", "object"},
                             {"parent", "world"},
                             {"pose", {{"position_m", {at.x(), at.y(), at.z()}}, {"rpy_deg", {0, 0, 30}}}},
                             {"model",
                              {{"frame", "a corner of the plate's bottom face"},
                               {"static", true},
                               {"step", "imported/plate.step"}}}});
  std::ofstream(laptop_ / "cell.json") << doc.dump(2);
  const std::string plate_pointer = "/entities/" + std::to_string(doc["entities"].size() - 1) + "/model";

  // Without its model the world model cannot read the plate: refused, naming where, and nothing changes.
  const CtlResult bare = run_riggerctl(cell_, "apply-bare", {"cell", "apply", (laptop_ / "cell.json").string()});
  EXPECT_NE(bare.code(), 0) << bare.output;
  EXPECT_NE(bare.output.find(plate_pointer + "/step"), std::string::npos) << bare.output;
  EXPECT_NE(bare.output.find("imported/plate.step"), std::string::npos) << bare.output;
  EXPECT_EQ(models_seen_.count(plate_sha256_), 0U);

  // With it: pinned by its sha256, kept by the world model, published for the followers.
  const CtlResult sent = run_riggerctl(cell_, "apply-with-models",
                                       {"cell", "apply", (laptop_ / "cell.json").string(), "--with-models",
                                        "--comment", "the plate, from a laptop"});
  ASSERT_EQ(sent.code(), 0) << sent.output << cell_.logs();
  EXPECT_NE(sent.output.find("cell revision 2"), std::string::npos) << sent.output;
  ASSERT_TRUE(cell_.wait_until([&] { return models_seen_.count(plate_sha256_) > 0; }, 10s))
      << "the world model did not publish the plate's model";

  // cell_sim builds it into its running model from the bytes it received: the plate is where it was put.
  ASSERT_TRUE(service_detail_says(cell_, "cell_sim", "cell revision 2", 30s)) << cell_.logs();
  ASSERT_TRUE(cell_.wait_until([&] { return truth_.count("plate") > 0; }, 10s)) << "no ground truth of the plate";
  const double off_mm = 1e3 * (truth_["plate"].translation() - at).norm();
  std::printf("  plate in the physics: %.3f mm from its pose in the revision\n", off_mm);
  EXPECT_LT(off_mm, 1.0);

  // The CAD service answers the plate's features from the same bytes: its three holes.
  ASSERT_TRUE(service_detail_says(cell_, "cad", "cell revision 2", 30s)) << cell_.logs();
  ASSERT_TRUE(cell_.wait_until([&] { return cad_requests_.matched_readers() > 0 && cad_replies_.matched_writers() > 0; }, 10s));
  const CadAnswer features = cad_call(rigger_cad_CAD_FEATURES, "object:plate");
  ASSERT_TRUE(features.ok) << features.why;
  EXPECT_EQ(features.sha256, plate_sha256_);
  EXPECT_EQ(json::parse(features.result_json)["holes"].size(), 3U);

  // A restarted world model runs revision 2 again, the plate's model from its own store, and publishes it.
  const int before = models_seen_[plate_sha256_];
  ASSERT_TRUE(cell_.stop("world_model", SIGTERM, 10s).has_value());
  start_world_model("world_model-2");
  ASSERT_TRUE(cell_.wait_ready({"world_model"}, 60s)) << cell_.logs();
  EXPECT_TRUE(cell_.wait_until([&] { return models_seen_[plate_sha256_] > before; }, 10s))
      << "the restarted world model did not publish the plate's model again";
  const CtlResult history = run_riggerctl(cell_, "history", {"cell", "history"});
  EXPECT_NE(history.output.find("the plate, from a laptop"), std::string::npos) << history.output;
}

}  // namespace
}  // namespace rigger::testing
