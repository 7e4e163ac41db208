// The cad process over real DDS: it answers by correlation id, serves the cell's object models
// (GLB for the web console), refuses bad requests with a code, and keeps answering after a STEP file
// that crashes OCCT's reader (the time limit is tested in common/cad's unit tests).
#include <signal.h>

#include <fstream>
#include <map>
#include <optional>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "rigger/dds/conversions.hpp"
#include "rigger/dds/pubsub.hpp"
#include "rigger/dds/sequences.hpp"
#include "rigger/protocol/cad.hpp"
#include "rigger/testing/cell.hpp"

namespace rigger::testing {
namespace {

using namespace std::chrono_literals;

struct Answer {
  bool ok = false;
  std::string code, message, sha256, result_json;
  std::size_t data_bytes = 0;
  std::string data_head;
};

class CadServiceTest : public MultiProcessTest {
 protected:
  void SetUp() override {
    const std::string config = cell_.log_dir() + "/cad.json";
    // The test's models are the source tree's fixtures: named absolutely (a service finds relative paths
    // beside its configuration or in the installation, never in the source tree).
    std::ofstream(config) << R"({"allowed_dirs": ["/usr/share/opencascade/data/step", ")" RIGGER_SOURCE_DIR
                             R"(/common/cad/test/data"]})";
    cell_.start("cad", "cad", {"--id", "cad", "--config", config});
    ASSERT_TRUE(cell_.wait_ready({"cad"}, 30s)) << cell_.logs();
    requests_.emplace(cell_.participant(), protocol::cad::kRequest);
    replies_.emplace(cell_.participant(), protocol::cad::kReply);
    cell_.loop().on_data(*replies_, [this] {
      replies_->take([this](const rigger_cad_CadReply& r, const dds_sample_info_t&) {
        if (dds::to_string(r.client_id) != "cad-test") return;
        const auto data = dds::elements(r.data);
        Answer a{r.ok,
                 dds::to_string(r.code),
                 dds::to_string(r.message),
                 dds::to_string(r.model_sha256),
                 dds::to_string(r.result_json),
                 data.size(),
                 ""};
        if (data.size() >= 4) a.data_head.assign(reinterpret_cast<const char*>(data.data()), 4);
        answers_[r.request_id] = a;
      });
    });
    ASSERT_TRUE(cell_.wait_until([&] { return requests_->matched_readers() > 0 && replies_->matched_writers() > 0; }, 10s));
  }

  Answer call(rigger_cad_CadRequestKind kind, const std::string& model, const std::string& args = "") {
    const std::uint64_t id = ++next_id_;
    rigger_cad_CadRequest request{};
    request.client_id = dds::wire_string(client_id_);
    request.request_id = id;
    request.kind = kind;
    request.model = dds::wire_string(model);
    request.args_json = dds::wire_string(args);
    EXPECT_EQ(requests_->write(request), DDS_RETCODE_OK);
    EXPECT_TRUE(cell_.wait_until([&] { return answers_.count(id) > 0; }, 20s)) << "no answer to request " << id;
    return answers_[id];
  }

  std::string client_id_ = "cad-test";
  std::uint64_t next_id_ = 100;
  std::optional<dds::Writer<rigger_cad_CadRequest>> requests_;
  std::optional<dds::Reader<rigger_cad_CadReply>> replies_;
  std::map<std::uint64_t, Answer> answers_;
};

TEST_F(CadServiceTest, AnswersTheConsolesQueriesAndSurvivesBadInput) {
  const Answer mesh = call(rigger_cad_CAD_TESSELLATION, "object:target");
  ASSERT_TRUE(mesh.ok) << mesh.code << ": " << mesh.message;
  EXPECT_EQ(mesh.data_head, "glTF");
  EXPECT_EQ(nlohmann::json::parse(mesh.result_json)["parts"].size(), 14u);
  const Answer features = call(rigger_cad_CAD_FEATURES, "object:target");
  ASSERT_TRUE(features.ok) << features.message;
  EXPECT_EQ(nlohmann::json::parse(features.result_json)["holes"].size(), 4u);
  EXPECT_EQ(features.sha256, mesh.sha256);

  EXPECT_EQ(call(rigger_cad_CAD_FEATURES, "object:nothing").code, "CAD_UNKNOWN_MODEL");
  EXPECT_EQ(call(rigger_cad_CAD_LOAD, "/etc/passwd").code, "CAD_FORBIDDEN_PATH");
  // OCCT's reader segfaults on this file (found by the fuzzer): its child dies, the service does not.
  const Answer crashed = call(rigger_cad_CAD_FEATURES, RIGGER_SOURCE_DIR "/common/cad/test/data/occt_segv_face_bound.step");
  EXPECT_EQ(crashed.code, "CAD_READER_CRASHED") << crashed.message;
  // Still answering, and right.
  const Answer screw = call(rigger_cad_CAD_LOAD, "/usr/share/opencascade/data/step/screw.step");
  ASSERT_TRUE(screw.ok) << screw.message;
  EXPECT_EQ(nlohmann::json::parse(screw.result_json)["counts"]["faces"], 10);
  const Answer hole = call(rigger_cad_CAD_FRAME, "object:load", R"({"rule": "hole", "hole": 0})");
  ASSERT_TRUE(hole.ok) << hole.message;
  EXPECT_NEAR(nlohmann::json::parse(hole.result_json)["frame"]["position_m"][2].get<double>(), 0.10, 1e-9);
}

}  // namespace
}  // namespace rigger::testing
