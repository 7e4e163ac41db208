// The console's HTTP side at its limits: live streams beyond max_streams, and the Planner's STEP import
// with a body limit of its own (see http_api_fixture.hpp for the recording Backend in place of DDS).
#include "http_api_fixture.hpp"

namespace rigger::console::testing {
namespace {

using nlohmann::json;
using namespace std::chrono_literals;

class HttpApiFewStreamsTest : public HttpApiTest {
 protected:
  void configure(HttpConfig& config) override { config.max_streams = 2; }
};

// Every live stream holds a worker thread: one more than max_streams is refused with 503 and Retry-After
// rather than queued behind the others (where it would wait for ever), the pages' requests are still
// served, and a stream that ends gives its slot back.
TEST_F(HttpApiFewStreamsTest, StreamsBeyondTheLimitAreRefusedAndRequestsStillServed) {
  struct Stream {
    std::unique_ptr<httplib::Client> client;
    std::atomic<bool> open{false}, stop{false}, ended{false};
    std::thread reader;
  };
  const auto open_stream = [&](Stream& s) {
    s.client = std::make_unique<httplib::Client>("127.0.0.1", api_->port());
    s.reader = std::thread([&] {
      s.client->Get("/api/events", as(kVic), [&](const char*, std::size_t) {
        s.open = true;
        return !s.stop.load();
      });
      s.ended = true;
    });
  };
  // Events keep flowing, so that each stream writes (and notices a closed client) in its own time.
  int seq = 0;
  const auto until = [&](const std::function<bool()>& done) {
    for (const auto deadline = std::chrono::steady_clock::now() + 10s; std::chrono::steady_clock::now() < deadline;) {
      state_.update_node({{"task_id", "t"}, {"node_id", "n" + std::to_string(++seq)}, {"state", "RUNNING"}});
      if (done()) return true;
      std::this_thread::yield();
    }
    return false;
  };
  Stream a, b;
  open_stream(a);
  open_stream(b);
  ASSERT_TRUE(until([&] { return a.open && b.open; })) << "two streams within the limit";
  const auto third = client_->Get("/api/events", as(kVic));
  ASSERT_TRUE(third);
  EXPECT_EQ(third->status, 503);
  EXPECT_NE(third->body.find("at most 2 live streams at once (max_streams)"), std::string::npos) << third->body;
  EXPECT_EQ(third->get_header_value("Retry-After"), "5");
  const auto me = client_->Get("/api/me", as(kVic));
  ASSERT_TRUE(me);
  EXPECT_EQ(me->status, 200) << "a page's request is served while the streams are open";
  // One stream ends: its slot comes back (a stream that opens receives data; a refusal does not).
  a.stop = true;
  EXPECT_TRUE(until([&] {
    bool streamed = false;
    client_->Get(
        "/api/events", as(kVic),
        [&](const httplib::Response& r) {
          streamed = r.status == 200;
          return false;
        },
        [](const char*, std::size_t) { return false; });
    return streamed;
  })) << "a stream opens again once one has ended";
  b.stop = true;
  EXPECT_TRUE(until([&] { return a.ended && b.ended; }));
  a.reader.join();
  b.reader.join();
}

class HttpApiImportTest : public HttpApiTest {
 protected:
  void configure(HttpConfig& config) override { config.max_import_bytes = 256 * 1024; }
};

// A STEP file to import goes to the CAD service as bytes, bounded by its own limit (larger than a JSON
// body's, smaller here); the CAD service's refusal keeps its code; programmers only; audited.
TEST_F(HttpApiImportTest, AStepFileIsReadByTheCadServiceWithinItsOwnLimit) {
  const auto send = [&](const std::string& path, const std::string& bytes, int user) {
    return client_->Post(path.c_str(), as(user), bytes, "application/octet-stream");
  };
  const std::string file(100 * 1024, 'x');  // above max_body_bytes (64 KiB), within the import's limit
  EXPECT_EQ(send("/api/planner/import?name=bracket.step", file, kVic)->status, 403);
  EXPECT_EQ(send("/api/planner/import?name=bracket.step", "", kAda)->status, 400);
  EXPECT_EQ(send("/api/planner/import?name=a/b.step", file, kAda)->status, 400);
  auto r = send("/api/planner/import?name=bracket.step", std::string(300 * 1024, 'x'), kAda);
  EXPECT_EQ(r->status, 413) << r->body;
  EXPECT_TRUE(backend_.cad_requests().empty()) << "nothing reached the CAD service";

  backend_.cad_answer_ = {false, "CAD_NO_UNITS: bracket.step: the file declares no length unit", {}};
  r = send("/api/planner/import?name=bracket.step", file, kAda);
  EXPECT_EQ(r->status, 400);
  EXPECT_NE(body(r)["error"].get<std::string>().find("CAD_NO_UNITS"), std::string::npos) << r->body;
  EXPECT_EQ(backend_.cad_requests().back(), "load bracket.step 102400 bytes");

  backend_.cad_answer_ = {true, "", json{{"model_sha256", "ab12"},
                                        {"result", {{"units", "m"}, {"source", "content"},
                                                    {"product", {{"name", "BRACKET"}, {"assembly", false}}}}}}};
  r = send("/api/planner/import?name=bracket.step", file, kAda);
  ASSERT_EQ(r->status, 200) << r->body;
  EXPECT_EQ(body(r)["model"], "sha256:ab12");
  EXPECT_EQ(body(r)["product"]["name"], "BRACKET");
  EXPECT_EQ(body(r)["bytes"], 102400);
  EXPECT_FALSE(body(r).contains("source"));
  // JSON endpoints keep their own, smaller limit.
  EXPECT_EQ(post("/api/planner/validate", std::string(100 * 1024, ' '), kAda)->status, 413);
  std::ifstream audit(dir_ + "/audit.log");
  const std::string text{std::istreambuf_iterator<char>(audit), std::istreambuf_iterator<char>()};
  EXPECT_NE(text.find(R"("action":"import STEP","result":"read as sha256:ab12")"), std::string::npos) << text;
}

// One of the cell's own models imported again, by its sha256: the CAD service reads the cell's bytes,
// named as the cell names the file; a model the cell does not pin is not found, and a request that also
// sends bytes is refused before anything is read.
TEST_F(HttpApiImportTest, AModelOfTheCellIsImportedByItsSha256) {
  const std::string sha(64, 'c');
  backend_.cell_models_[sha] = {sha, "models/flange.step", std::string(2000, 's')};
  auto r = client_->Get("/api/planner/cell_models", as(kAda));
  ASSERT_EQ(r->status, 200) << r->body;
  EXPECT_EQ(body(r), json::parse(R"([{"name":"models/flange.step","sha256":")" + sha + R"(","bytes":2000}])"));
  EXPECT_EQ(client_->Get("/api/planner/cell_models", as(kVic))->status, 403);

  backend_.cad_answer_ = {true, "", json{{"model_sha256", sha}, {"result", {{"units", "m"}}}}};
  const auto send = [&](const std::string& path, const std::string& bytes) {
    return client_->Post(path.c_str(), as(kAda), bytes, "application/octet-stream");
  };
  r = send("/api/planner/import?model=" + std::string(64, 'd'), "");
  EXPECT_EQ(r->status, 404) << r->body;
  EXPECT_EQ(send("/api/planner/import?model=" + sha, "bytes too")->status, 400);
  EXPECT_TRUE(backend_.cad_requests().empty()) << "nothing reached the CAD service";
  r = send("/api/planner/import?model=" + sha, "");
  ASSERT_EQ(r->status, 200) << r->body;
  EXPECT_EQ(body(r)["name"], "flange.step");
  EXPECT_EQ(body(r)["model_sha256"], sha);
  EXPECT_EQ(backend_.cad_requests().back(), "load flange.step 2000 bytes");
}

// An imported file made a cell object: refused while a task runs on the cell (the simulator would build
// it into the running physics), and when the console no longer keeps the file; nothing reaches the world
// model either way.
TEST_F(HttpApiImportTest, AnImportedPartIsNotAddedWhileATaskRunsOrWhenItsFileIsGone) {
  backend_.cad_answer_ = {true, "", json{{"model_sha256", std::string(64, 'a')}, {"result", {{"units", "m"}}}}};
  ASSERT_EQ(client_->Post("/api/planner/import?name=plate.step", as(kAda), std::string(1000, 'x'),
                          "application/octet-stream")->status, 200);
  const json add = {{"model", "sha256:" + std::string(64, 'a')}, {"id", "plate"}, {"material", "steel"}};
  state_.update_task({{"task_id", "t1"}, {"state", "RUNNING"}});
  auto r = post("/api/planner/add", add.dump(), kAda);
  EXPECT_EQ(r->status, 409) << r->body;
  EXPECT_NE(body(r)["error"].get<std::string>().find("1 task runs on the cell"), std::string::npos) << r->body;
  json gone = add;
  gone["model"] = "sha256:" + std::string(64, 'b');
  r = post("/api/planner/add", gone.dump(), kAda);
  EXPECT_EQ(r->status, 409) << r->body;
  EXPECT_NE(body(r)["error"].get<std::string>().find("import it again"), std::string::npos) << r->body;
  EXPECT_EQ(post("/api/planner/add", add.dump(), kVic)->status, 403);
  EXPECT_TRUE(backend_.actions().empty()) << "nothing reached the world model";
}

// An imported file as the new version of an object's model: refused while a task runs on the cell, when
// the console no longer keeps the file and for a viewer; nothing reaches the world model.
TEST_F(HttpApiImportTest, AModelIsNotReplacedWhileATaskRunsOrWhenItsFileIsGone) {
  backend_.cad_answer_ = {true, "", json{{"model_sha256", std::string(64, 'a')}, {"result", {{"units", "m"}}}}};
  ASSERT_EQ(client_->Post("/api/planner/import?name=plate-v2.step", as(kAda), std::string(1000, 'x'),
                          "application/octet-stream")->status, 200);
  const json replace = {{"model", "sha256:" + std::string(64, 'a')}, {"object", "plate"}};
  state_.update_task({{"task_id", "t1"}, {"state", "RUNNING"}});
  auto r = post("/api/planner/replace", replace.dump(), kAda);
  EXPECT_EQ(r->status, 409) << r->body;
  EXPECT_NE(body(r)["error"].get<std::string>().find("1 task runs on the cell: replace the model once it has ended"),
            std::string::npos) << r->body;
  json gone = replace;
  gone["model"] = "sha256:" + std::string(64, 'b');
  r = post("/api/planner/replace", gone.dump(), kAda);
  EXPECT_EQ(r->status, 409) << r->body;
  EXPECT_NE(body(r)["error"].get<std::string>().find("import it again"), std::string::npos) << r->body;
  json bad = replace;
  bad.erase("object");
  r = post("/api/planner/replace", bad.dump(), kAda);
  EXPECT_EQ(r->status, 400) << r->body;
  EXPECT_EQ(post("/api/planner/replace", replace.dump(), kVic)->status, 403);
  EXPECT_TRUE(backend_.actions().empty()) << "nothing reached the world model";
}

// A node of an imported file: the CAD service gets the file's bytes and the node's path (CAD_LOAD with
// args_json.node), the console keeps the node's own STEP bytes under their sha256 (Add then takes them);
// a bad path is refused before anything is read, the CAD service's refusal at #/node, a file the console no
// longer keeps as gone.
TEST_F(HttpApiImportTest, ANodeOfAnImportedFileBecomesAFileOfItsOwn) {
  const std::string file_sha(64, 'a'), node_sha(64, 'e');
  backend_.cad_answer_ = {true, "", json{{"model_sha256", file_sha}, {"result", {{"units", "m"}}}}};
  ASSERT_EQ(client_->Post("/api/planner/import?name=cell_assembly.step", as(kAda), std::string(1000, 'x'),
                          "application/octet-stream")->status, 200);
  const json choose = {{"model", "sha256:" + file_sha}, {"node", {1, 0}}};
  EXPECT_EQ(post("/api/planner/import/node", choose.dump(), kVic)->status, 403);
  for (const json& bad : {json{{"model", "sha256:" + file_sha}, {"node", {1, -1}}}, json{{"model", "sha256:" + file_sha}, {"node", "1/0"}},
                          json{{"model", "a.step"}, {"node", json::array()}}}) {
    const auto r = post("/api/planner/import/node", bad.dump(), kAda);
    EXPECT_EQ(r->status, 400) << r->body;
  }
  EXPECT_NE(body(post("/api/planner/import/node", json{{"model", "sha256:" + file_sha}, {"node", {1, -1}}}.dump(), kAda))["where"]
                .get<std::string>().find("#/node/1"), std::string::npos);
  EXPECT_EQ(backend_.cad_requests().size(), 1u) << "only the import reached the CAD service";
  json gone = choose;
  gone["model"] = "sha256:" + std::string(64, 'b');
  EXPECT_EQ(post("/api/planner/import/node", gone.dump(), kAda)->status, 409);

  backend_.cad_answer_ = {false, "CAD_BAD_REFERENCE: STEP input cell_assembly.step has no node 1/0: the root has 1 component", {}};
  auto r = post("/api/planner/import/node", choose.dump(), kAda);
  EXPECT_EQ(r->status, 400) << r->body;
  EXPECT_EQ(body(r)["where"], "/api/planner/import/node#/node") << r->body;
  EXPECT_EQ(backend_.cad_requests().back(), R"(load cell_assembly.step 1000 bytes {"node":[1,0]})");

  backend_.cad_answer_ = {true, "", json{{"model_sha256", node_sha}, {"data", "ISO-10303-21; the node"},
                                        {"result", {{"units", "m"}, {"source", "content node 1/0"},
                                                    {"node", {{"path", {1, 0}}, {"name", "left block"}, {"instance", "b1"}}}}}}};
  r = post("/api/planner/import/node", choose.dump(), kAda);
  ASSERT_EQ(r->status, 200) << r->body;
  EXPECT_EQ(body(r)["model"], "sha256:" + node_sha);
  EXPECT_EQ(body(r)["name"], "left_block.step");
  EXPECT_EQ(body(r)["bytes"], 22);
  EXPECT_EQ(body(r)["file"]["model"], "sha256:" + file_sha);
  EXPECT_FALSE(body(r).contains("source"));
  // Kept: Add finds the node's file (and is refused here only because a task runs).
  state_.update_task({{"task_id", "t1"}, {"state", "RUNNING"}});
  r = post("/api/planner/add", json{{"model", "sha256:" + node_sha}, {"id", "left_block"}, {"material", "steel"}}.dump(), kAda);
  EXPECT_EQ(r->status, 409) << r->body;
  EXPECT_NE(body(r)["error"].get<std::string>().find("1 task runs on the cell"), std::string::npos) << r->body;
  std::ifstream audit(dir_ + "/audit.log");
  const std::string text{std::istreambuf_iterator<char>(audit), std::istreambuf_iterator<char>()};
  EXPECT_NE(text.find(R"("action":"import STEP node")"), std::string::npos) << text;
}

// cpp-httplib 0.11 compresses with brotli at quality 11 whenever a client accepts br, as every
// browser does (1.8 s of CPU for three.js per page load): JSON and JavaScript go out uncompressed.
}  // namespace
}  // namespace rigger::console::testing
