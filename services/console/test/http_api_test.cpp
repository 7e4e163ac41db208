// The console's HTTP side over real loopback HTTP (cpp-httplib's client), with a recording Backend in
// place of DDS: who may do what, the two-step confirmation, bounded bodies, and the event stream's
// resume from Last-Event-ID.
#include "http_api_fixture.hpp"

namespace rigger::console::testing {
namespace {

using nlohmann::json;
using namespace std::chrono_literals;

TEST_F(HttpApiTest, EveryRequestNeedsAKnownTokenAndTheRightRole) {
  auto r = client_->Get("/api/me");
  ASSERT_TRUE(r);
  EXPECT_EQ(r->status, 401);
  EXPECT_EQ(body(r)["where"], "/api/me");
  r = client_->Get("/api/me", {{"Authorization", "Bearer nope"}});
  EXPECT_EQ(r->status, 401);
  r = client_->Get("/api/me", as(kVic));
  EXPECT_EQ(r->status, 200);
  EXPECT_EQ(body(r)["role"], "viewer");
  r = post("/api/recipes", R"({"task_id": "t"})");
  EXPECT_EQ(r->status, 401);
  r = post("/api/recipes", R"({"task_id": "t"})", kOlu);
  EXPECT_EQ(r->status, 403);
  EXPECT_NE(body(r)["error"].get<std::string>().find("programmer"), std::string::npos);
  state_.update_prompt({{"prompt_id", "p1"}, {"active", true}, {"options", {"done", "failed"}}});
  r = post("/api/prompts/p1/answer", R"({"answer": "done"})", kVic);
  EXPECT_EQ(r->status, 403);
  r = post("/api/prompts/p1/answer", R"({"answer": "maybe"})", kOlu);
  EXPECT_EQ(r->status, 400);
  r = post("/api/prompts/p2/answer", R"({"answer": "done"})", kOlu);
  EXPECT_EQ(r->status, 409);
  EXPECT_TRUE(backend_.actions().empty()) << "a refused request reached DDS";
  r = post("/api/prompts/p1/answer", R"({"answer": "done", "comment": 5})", kOlu);
  EXPECT_EQ(r->status, 200);
  EXPECT_EQ(backend_.actions(), std::vector<std::string>{"answer p1 done by olu"});
}

TEST_F(HttpApiTest, RunsServeTheirPlotsFromDiskToViewers) {
  runs_->on_task("insert", "RUNNING", 10);
  runs_->on_row(R"({"t":10.5,"f":3.25})");
  runs_->on_cell(json::parse(R"({"t":10.6,"hook":[1,2,3]})"));
  runs_->on_task("insert", "SUCCEEDED", 11);
  auto r = client_->Get("/api/runs", as(kVic));
  ASSERT_TRUE(r);
  ASSERT_EQ(r->status, 200);
  EXPECT_EQ(body(r)["runs"][0]["task_id"], "insert");
  EXPECT_EQ(body(r)["runs"][0]["state"], "SUCCEEDED");
  r = client_->Get("/api/runs/insert/plots", as(kVic));
  ASSERT_EQ(r->status, 200);
  EXPECT_EQ(body(r), json::parse(R"([{"t":10.5,"f":3.25}])"));
  r = client_->Get("/api/runs/other/plots", as(kVic));
  EXPECT_EQ(r->status, 404);
  EXPECT_NE(body(r)["error"].get<std::string>().find("'other'"), std::string::npos);
  EXPECT_EQ(client_->Get("/api/runs/insert/plots")->status, 401);
  r = client_->Get("/api/runs/insert/cell", as(kVic));
  ASSERT_EQ(r->status, 200);
  EXPECT_EQ(body(r), json::parse(R"([{"t":10.6,"hook":[1,2,3]}])"));
  EXPECT_EQ(client_->Get("/api/runs/other/cell", as(kVic))->status, 404);
  EXPECT_EQ(client_->Get("/api/runs/insert/cell")->status, 401);
}

TEST_F(HttpApiTest, PublishIsSelectThenConfirmInTimeByTheSameUser) {
  auto r = post("/api/recipes", R"({"task_id": "t1", "tree": {}})", kAda);
  ASSERT_EQ(r->status, 202);
  const std::string id = body(r)["confirmation_id"];
  EXPECT_TRUE(backend_.actions().empty()) << "selecting must not publish";
  r = post("/api/confirm", json{{"confirmation_id", id}}.dump(), kOlu);
  EXPECT_EQ(r->status, 409) << "another user's selection";
  r = post("/api/confirm", json{{"confirmation_id", id}}.dump(), kAda);
  EXPECT_EQ(r->status, 200);
  r = post("/api/confirm", json{{"confirmation_id", id}}.dump(), kAda);
  EXPECT_EQ(r->status, 409) << "a confirmation is used once";
  EXPECT_EQ(backend_.actions(), std::vector<std::string>{"publish t1 by console:ada"});

  r = post("/api/recipes", R"({"task_id": "t2"})", kAda);
  const std::string late = body(r)["confirmation_id"];
  std::this_thread::sleep_for(400ms);  // past confirm_timeout (300 ms): the expiry is what is tested
  r = post("/api/confirm", json{{"confirmation_id", late}}.dump(), kAda);
  EXPECT_EQ(r->status, 409);
  EXPECT_NE(body(r)["error"].get<std::string>().find("expired"), std::string::npos);
  EXPECT_EQ(backend_.actions().size(), 1U) << "nothing more was published";
}

TEST_F(HttpApiTest, ACellRevisionIsCheckedThenConfirmedByAProgrammerAndAudited) {
  const std::string cell = R"({"cell": {"cell_version": 1, "entities": []}, "comment": "part moved"})";
  EXPECT_EQ(post("/api/cell/revisions", cell, kOlu)->status, 403);
  EXPECT_EQ(post("/api/cell/revisions", cell, kVic)->status, 403);
  EXPECT_EQ(post("/api/cell/revisions", R"({"cell": "not an object"})", kAda)->status, 400);
  EXPECT_TRUE(backend_.actions().empty()) << "a refused request reached the world model";
  auto r = post("/api/cell/revisions", cell, kAda);
  ASSERT_EQ(r->status, 202) << r->body;
  EXPECT_EQ(body(r)["changes"]["moved"][0]["id"], "part") << "the dry run's diff is shown before the confirmation";
  const std::string id = body(r)["confirmation_id"];
  EXPECT_EQ(backend_.actions(), std::vector<std::string>{R"(cell apply dry by console:ada {"cell_version":1,"entities":[]})"});
  EXPECT_EQ(post("/api/confirm", json{{"confirmation_id", id}}.dump(), kOlu)->status, 409) << "another user's selection";
  r = post("/api/confirm", json{{"confirmation_id", id}}.dump(), kAda);
  ASSERT_EQ(r->status, 200) << r->body;
  EXPECT_EQ(body(r)["cell_revision"], 2);
  EXPECT_EQ(backend_.actions().back(), R"(cell apply by console:ada {"cell_version":1,"entities":[]})");
  EXPECT_EQ(post("/api/confirm", json{{"confirmation_id", id}}.dump(), kAda)->status, 409) << "used once";
  // A rollback, the same two steps.
  r = post("/api/cell/revisions", R"({"rollback": 1})", kAda);
  ASSERT_EQ(r->status, 202) << r->body;
  r = post("/api/confirm", json{{"confirmation_id", body(r)["confirmation_id"]}}.dump(), kAda);
  EXPECT_EQ(r->status, 200);
  EXPECT_EQ(backend_.actions().back(), "cell rollback 1 by console:ada");
  std::ifstream audit(dir_ + "/audit.log");
  const std::string text((std::istreambuf_iterator<char>(audit)), std::istreambuf_iterator<char>());
  EXPECT_NE(text.find(R"("action":"cell apply")"), std::string::npos) << text;
  EXPECT_NE(text.find("revision 2"), std::string::npos) << text;
}

TEST_F(HttpApiTest, TheWorldModelsCellCodesBecomeHttpStatuses) {
  const auto refuse = [](const char* code, const char* why) { return ActionResult{false, why, {{"code", code}, {"cell_revision", 1}}}; };
  backend_.cell_check_ = refuse("INVALID", "cell.json: /entities/3/model/mass_kg: expected a mass > 0");
  auto r = post("/api/cell/revisions", R"({"cell": {}})", kAda);
  EXPECT_EQ(r->status, 422);
  EXPECT_NE(body(r)["error"].get<std::string>().find("/entities/3/model/mass_kg"), std::string::npos) << r->body;
  backend_.cell_check_ = refuse("UNKNOWN_REVISION", "no revision 9");
  EXPECT_EQ(post("/api/cell/revisions", R"({"rollback": 9})", kAda)->status, 404);
  backend_.cell_check_ = ActionResult{false, "no world model answers cell requests on this domain", {}};
  EXPECT_EQ(post("/api/cell/revisions", R"({"rollback": 1})", kAda)->status, 503);
  // A task took hold of the part between the check and the confirmation: 409, and nothing applied.
  backend_.cell_check_ = backend_.cell_answer_;
  backend_.cell_answer_ = refuse("HELD_BY_TASK", "part is held by task t1, node root/2");
  r = post("/api/cell/revisions", R"({"cell": {}})", kAda);
  ASSERT_EQ(r->status, 202);
  r = post("/api/confirm", json{{"confirmation_id", body(r)["confirmation_id"]}}.dump(), kAda);
  EXPECT_EQ(r->status, 409);
  EXPECT_NE(body(r)["error"].get<std::string>().find("HELD_BY_TASK: part is held by task t1"), std::string::npos) << r->body;
  // The history and the running revision, for viewers.
  backend_.cell_answer_ = {true, "", {{"code", "ACCEPTED"}, {"cell_revision", 3}, {"result", {{"revisions", json::array({{{"cell_revision", 3}}})}}}}};
  r = client_->Get("/api/cell/history", as(kVic));
  ASSERT_EQ(r->status, 200);
  EXPECT_EQ(body(r)["cell_revision"], 3);
  EXPECT_EQ(body(r)["revisions"][0]["cell_revision"], 3);
  EXPECT_EQ(client_->Get("/api/cell/history")->status, 401);
}

TEST_F(HttpApiTest, AFeatureDeclaredByPicksIsARevisionDryRunOfTheRunningDocument) {
  const json running = {{"cell_version", 1}, {"entities", {{{"id", "target"}}}}};
  backend_.cell_answer_ = {true, "", {{"code", "OK"}, {"cell_revision", 4}, {"result", {{"cell_json", running.dump()}}}}};
  const json face = {{"index", 0}, {"normal", {0, 0, 1}},
                     {"signature", {{"type", "plane"}, {"centroid_m", {0, 0, 0.02}}, {"direction", {0, 0, 1}}, {"radius_m", 0}}}};
  const json edge = {{"index", 0}, {"signature", {{"type", "line"}, {"centroid_m", {0, 0.1, 0.02}}, {"direction", {0, 0, 1}}, {"radius_m", 0}}}};
  backend_.cad_answer_ = {true, "", {{"model_sha256", "ab"}, {"result", {{"faces", {face}}, {"edges", {edge}}, {"holes", json::array()}}}}};
  const json declare = {{"model", "object:target"}, {"kind", "grasp_frame"}, {"name", "g"}, {"face", 0}};
  EXPECT_EQ(post("/api/planner/declare", declare.dump(), kOlu)->status, 403);
  auto r = post("/api/planner/declare", declare.dump(), kAda);
  ASSERT_EQ(r->status, 202) << r->body;
  EXPECT_EQ(body(r)["features"], json({"target/g"}));
  EXPECT_EQ(body(r)["base_revision"], 4);
  EXPECT_EQ(backend_.cad_requests().back(), "features object:target {}");
  const std::string dry = backend_.actions().back();
  EXPECT_EQ(dry.rfind("cell apply dry by console:ada ", 0), 0u) << dry;
  EXPECT_NE(dry.find(R"("grasp_frames":[{"cad":{"face":{"index":0,"kind":"face")"), std::string::npos) << dry;
  // Picks that make no frame: 400 at the field, and no dry run.
  json bad = declare;
  bad["x_edge"] = 0;  // along the face's normal
  const std::size_t before = backend_.actions().size();
  r = post("/api/planner/declare", bad.dump(), kAda);
  EXPECT_EQ(r->status, 400);
  EXPECT_EQ(body(r)["where"], "/api/planner/declare#/x_edge") << r->body;
  EXPECT_EQ(backend_.actions().size(), before + 1) << "only the running revision was read";
  // A task holds the object: the world model's dry run refuses, 409 with its reason.
  backend_.cell_check_ = {false, "target is held by task t1", {{"code", "HELD_BY_TASK"}, {"cell_revision", 4}}};
  r = post("/api/planner/declare", declare.dump(), kAda);
  EXPECT_EQ(r->status, 409);
  EXPECT_NE(body(r)["error"].get<std::string>().find("HELD_BY_TASK: target is held by task t1"), std::string::npos) << r->body;
}

TEST_F(HttpApiTest, MalformedAndOversizedBodiesAreRefusedBeforeParsing) {
  auto r = post("/api/recipes", R"({"task_id": 5)", kAda);
  EXPECT_EQ(r->status, 400);
  EXPECT_NE(body(r)["error"].get<std::string>().find("1:14"), std::string::npos) << r->body;
  r = post("/api/recipes", std::string(200, '[') + std::string(200, ']'), kAda);
  EXPECT_EQ(r->status, 400) << "nesting deeper than the bound";
  r = post("/api/recipes", R"([1, 2])", kAda);
  EXPECT_EQ(r->status, 400);
  r = post("/api/recipes", R"({"tree": {}})", kAda);
  EXPECT_EQ(r->status, 400);
  EXPECT_EQ(body(r)["where"], "/api/recipes#/task_id");
  r = post("/api/recipes", json{{"task_id", "big"}, {"pad", std::string(100 * 1024, 'x')}}.dump(), kAda);
  EXPECT_EQ(r->status, 413);
  EXPECT_TRUE(body(r).contains("error"));
  EXPECT_TRUE(backend_.actions().empty());
}

TEST_F(HttpApiTest, TheEventStreamResumesAfterLastEventIdAndResetsForAnotherRun) {
  state_.update_node({{"task_id", "t"}, {"node_id", "root"}, {"state", "RUNNING"}});  // 42:1
  state_.update_node({{"task_id", "t"}, {"node_id", "root/0"}, {"state", "RUNNING"}});  // 42:2
  state_.update_node({{"task_id", "t"}, {"node_id", "root/0"}, {"state", "SUCCESS"}});  // 42:3
  const auto read_stream = [&](const std::string& last_id, const std::string& until) {
    std::string got;
    auto headers = as(kVic);
    headers.emplace("Last-Event-ID", last_id);
    client_->Get("/api/events", headers, [&](const char* data, std::size_t n) {
      got.append(data, n);
      return got.find(until) == std::string::npos;
    });
    return got;
  };
  const std::string resumed = read_stream("42:1", "id: 42:3");
  EXPECT_EQ(resumed.find("id: 42:1\n"), std::string::npos) << "an event the client had is sent again";
  EXPECT_NE(resumed.find("id: 42:2\nevent: node\ndata: {"), std::string::npos) << resumed;
  EXPECT_LT(resumed.find("id: 42:2"), resumed.find("id: 42:3"));
  const std::string other_run = read_stream("41:7", "event: reset");
  EXPECT_NE(other_run.find("event: reset"), std::string::npos) << other_run;
  // The query token is accepted for the stream only.
  std::string got;
  auto r = client_->Get(("/api/events?last_event_id=42:2&token=" + created_[kVic].token).c_str(),
                        [&](const char* data, std::size_t n) {
                          got.append(data, n);
                          return got.find("id: 42:3") == std::string::npos;
                        });
  EXPECT_NE(got.find("id: 42:3"), std::string::npos);
  r = client_->Get(("/api/state?token=" + created_[kVic].token).c_str());
  EXPECT_EQ(r->status, 401);
}

TEST_F(HttpApiTest, JsonAndJavaScriptGoOutUncompressedEvenToAClientThatAcceptsBrotli) {
  const std::string script(64 * 1024, 'x');  // as compressible as text gets
  std::ofstream(dir_ + "/web/app.js") << script;
  httplib::Headers headers = as(2);
  headers.emplace("Accept-Encoding", "gzip, deflate, br");
  const auto js = client_->Get("/app.js", headers);
  ASSERT_TRUE(js);
  EXPECT_EQ(js->status, 200);
  EXPECT_EQ(js->get_header_value("Content-Type"), "application/javascript; charset=utf-8");
  EXPECT_FALSE(js->has_header("Content-Encoding")) << js->get_header_value("Content-Encoding");
  EXPECT_EQ(js->body, script);
  const auto me = client_->Get("/api/me", headers);
  ASSERT_TRUE(me);
  EXPECT_EQ(me->status, 200);
  EXPECT_EQ(me->get_header_value("Content-Type"), "application/json; charset=utf-8");
  EXPECT_FALSE(me->has_header("Content-Encoding")) << me->get_header_value("Content-Encoding");
  EXPECT_EQ(body(me).at("user"), "vic");
}

TEST_F(HttpApiTest, EveryActionIsInTheAuditLogWithItsUser) {
  state_.update_task({{"task_id", "t"}, {"state", "RUNNING"}});
  ASSERT_EQ(post("/api/tasks/t/stop", "{}", kOlu)->status, 200);
  ASSERT_EQ(post("/api/tasks/t/cancel", "{}", kOlu)->status, 403);
  EXPECT_EQ(post("/api/tasks/nope/pause", "{}", kOlu)->status, 404);
  EXPECT_EQ(backend_.actions(), std::vector<std::string>{"cancel t by console:olu"});
  std::ifstream in(dir_ + "/audit.log");
  std::string line;
  ASSERT_TRUE(std::getline(in, line));
  const json entry = json::parse(line);
  EXPECT_EQ(entry["user"], "olu");
  EXPECT_EQ(entry["action"], "stop");
  EXPECT_EQ(entry["target"], "t");
}

TEST_F(HttpApiTest, PlannerValidationIsTheControllersAndOnlyForProgrammers) {
  auto r = post("/api/planner/validate", R"({"recipe_version": 1, "task_id": "t", "root": {"type": "Skill", "skill": "Localize"}})", kOlu);
  EXPECT_EQ(r->status, 403);
  r = post("/api/planner/validate", R"({"recipe_version": 1, "task_id": "t", "root": {"type": "Skill", "skill": "Localize"}})", kAda);
  ASSERT_EQ(r->status, 200);
  // No executor announced a library: the controller's validator says the skill is unknown, by pointer.
  EXPECT_FALSE(body(r)["ok"].get<bool>());
  EXPECT_EQ(body(r)["errors"][0]["pointer"], "/root/skill") << r->body;
  EXPECT_TRUE(body(r).contains("canonical"));
  r = post("/api/planner/validate", R"({"task_id": )", kAda);
  ASSERT_EQ(r->status, 200);
  EXPECT_FALSE(body(r)["ok"].get<bool>());
  EXPECT_FALSE(body(r).contains("canonical"));
  r = client_->Get("/api/skills", as(kVic));
  ASSERT_EQ(r->status, 200);
  EXPECT_TRUE(body(r)["executors"].empty());
}

TEST_F(HttpApiTest, PlannerScrewsAskTheCadServiceAndTheWorldModelAndRefuseBadPicks) {
  auto r = post("/api/planner/screws", R"({"model": "object:target", "holes": [0]})", kVic);
  EXPECT_EQ(r->status, 403);
  r = post("/api/planner/screws", R"({"model": "object:target", "holes": "all"})", kAda);
  EXPECT_EQ(r->status, 400);
  EXPECT_EQ(body(r)["where"], "/api/planner/screws#/holes") << r->body;
  EXPECT_TRUE(backend_.cad_requests().empty()) << "a malformed request reached the CAD service";
  // No CAD service: 503, saying so.
  r = post("/api/planner/screws", R"({"model": "object:target", "holes": [0]})", kAda);
  EXPECT_EQ(r->status, 503);
  EXPECT_NE(body(r)["error"].get<std::string>().find("no CAD service"), std::string::npos) << r->body;
  // The CAD service refuses the pick (stale reference): 400 on the holes.
  backend_.cad_answer_ = {false, "CAD_STALE_REFERENCE: face 6 is now a plane", {}};
  r = post("/api/planner/screws", R"({"model": "object:target", "holes": [0]})", kAda);
  EXPECT_EQ(r->status, 400);
  EXPECT_EQ(body(r)["where"], "/api/planner/screws#/holes");
  // Both answer: the derived screw with the world model's feature.
  backend_.cad_answer_ = {true, "", json{{"model_sha256", "f00d"},
                                       {"result", {{"screws", {{{"hole", 0}, {"pose", {{"position_m", {-0.15, -0.1, 0.0}}}}}}}}}}};
  backend_.world_answer_ = {true, "", json{{"features", {{"screw_holes", {{{"id", "h1"}, {"position_m", {-0.15, -0.1, 0.0}}, {"torque_nm", 60}}}}}}}};
  r = post("/api/planner/screws", R"({"model": "object:target", "holes": [0]})", kAda);
  ASSERT_EQ(r->status, 200) << r->body;
  EXPECT_EQ(body(r)["model_sha256"], "f00d");
  EXPECT_EQ(body(r)["screws"][0]["feature"], "target/h1");
  ASSERT_FALSE(backend_.cad_requests().empty());
  EXPECT_EQ(backend_.cad_requests().back(), R"(derive object:target {"holes":[0],"parameter":"screw_list"})");
  // A hole the world model does not know.
  backend_.world_answer_ = {true, "", json{{"features", {{"screw_holes", json::array()}}}}};
  r = post("/api/planner/screws", R"({"model": "object:target", "holes": [0]})", kAda);
  EXPECT_EQ(r->status, 400);
  EXPECT_EQ(body(r)["where"], "/api/planner/screws#/holes/0") << r->body;
}


// --- Rehearsal: a recipe run first on the simulated cell of another domain ---

std::vector<json> audit_entries(const std::string& file) {
  std::ifstream in(file);
  std::vector<json> out;
  for (std::string line; std::getline(in, line);) out.push_back(json::parse(line));
  return out;
}

TEST_F(HttpApiTest, RehearseWithoutARehearsalDomainIsRefusedSayingWhatToConfigure) {
  const std::string recipe = R"({"recipe_version": 1, "task_id": "r1", "root": {"type": "Skill", "skill": "Localize"}})";
  auto r = post("/api/planner/rehearse", recipe);
  EXPECT_EQ(r->status, 401);
  r = post("/api/planner/rehearse", recipe, kVic);
  EXPECT_EQ(r->status, 403);
  r = post("/api/planner/rehearse", recipe, kOlu);
  EXPECT_EQ(r->status, 403);
  r = post("/api/planner/rehearse", recipe, kAda);
  ASSERT_EQ(r->status, 409);
  EXPECT_NE(body(r)["error"].get<std::string>().find("rehearsal_domain"), std::string::npos) << r->body;
  EXPECT_EQ(body(r)["where"], "/api/planner/rehearse");
  r = client_->Get("/api/rehearsal/state", as(kVic));
  EXPECT_EQ(r->status, 409);
  r = client_->Get("/api/rehearsal/events?token=" + created_[kVic].token);
  EXPECT_EQ(r->status, 409);
  EXPECT_TRUE(backend_.actions().empty());
  const auto audit = audit_entries(dir_ + "/audit.log");
  ASSERT_EQ(audit.size(), 1u);
  EXPECT_EQ(audit[0]["user"], "ada");
  EXPECT_EQ(audit[0]["action"], "rehearse");
  EXPECT_NE(audit[0]["result"].get<std::string>().find("refused"), std::string::npos);
}

class HttpApiRehearsalTest : public HttpApiTest {
 protected:
  std::optional<RehearsalFeed> rehearsal() override { return RehearsalFeed{7, rehearsal_state_, rehearsal_events_, watchers_}; }
  std::atomic<int> watchers_{0};
  EventLog rehearsal_events_{1000, "42"};
  ConsoleState rehearsal_state_{rehearsal_events_};
};

constexpr const char* kLocalize =
    R"({"recipe_version": 1, "task_id": "r1", "root": {"type": "Skill", "skill": "Localize", "params": {"object": "target"}}})";

TEST_F(HttpApiRehearsalTest, RehearseIsOneStepJournaledWithWhoAndAnswersWithTheRehearsalControllersVerdict) {
  // No controller reads recipes on the rehearsal domain: 503 with the backend's reason.
  backend_.rehearse_answer_ = {false, "no task controller reads recipes on the rehearsal domain 7; nothing was sent", {}};
  auto r = post("/api/planner/rehearse", kLocalize, kAda);
  ASSERT_EQ(r->status, 503) << r->body;
  EXPECT_NE(body(r)["error"].get<std::string>().find("no task controller"), std::string::npos);
  EXPECT_EQ(body(r)["domain"], 7);
  // The rehearsal controller's validator refuses it: 409 with its errors by pointer.
  backend_.rehearse_answer_ = {false, "the rehearsal controller refused the recipe: VALIDATION",
                               {{"state", "REJECTED"}, {"errors", {{{"pointer", "/root/skill"}, {"message", "unknown skill"}}}}}};
  r = post("/api/planner/rehearse", kLocalize, kAda);
  ASSERT_EQ(r->status, 409) << r->body;
  EXPECT_EQ(body(r)["errors"][0]["pointer"], "/root/skill") << r->body;
  // The rehearsal world model refuses the cell's running revision: 409 with its reason, nothing sent.
  backend_.rehearse_answer_ = {false,
                               "the rehearsal world model refused the cell's revision 3: INVALID: /entities/2/pose: "
                               "expected position_m; nothing was sent",
                               {{"cell_refused", true}}};
  r = post("/api/planner/rehearse", kLocalize, kAda);
  ASSERT_EQ(r->status, 409) << r->body;
  EXPECT_NE(body(r)["error"].get<std::string>().find("refused the cell's revision 3: INVALID: /entities/2/pose"),
            std::string::npos)
      << r->body;
  EXPECT_TRUE(backend_.actions().empty());
  // Viewers and operators may not; bad bodies are refused before anything is sent.
  EXPECT_EQ(post("/api/planner/rehearse", kLocalize, kVic)->status, 403);
  EXPECT_EQ(post("/api/planner/rehearse", kLocalize, kOlu)->status, 403);
  EXPECT_EQ(post("/api/planner/rehearse", R"({"recipe_version": 1})", kAda)->status, 400);
  EXPECT_EQ(post("/api/planner/rehearse", "{\"task_id\": ", kAda)->status, 400);
  EXPECT_EQ(post("/api/planner/rehearse", std::string(70 * 1024, ' '), kAda)->status, 413);
  // Accepted: one step (no confirmation; nothing real moves).
  backend_.rehearse_answer_ = {true, "", {{"state", "ACCEPTED"}}};
  r = post("/api/planner/rehearse", kLocalize, kAda);
  ASSERT_EQ(r->status, 200) << r->body;
  EXPECT_EQ(body(r)["domain"], 7);
  EXPECT_EQ(body(r)["state"], "ACCEPTED");
  EXPECT_EQ(backend_.actions(), std::vector<std::string>{"rehearse r1 by console:ada"});
  // The controller takes a task id once: a second rehearsal of r1 is refused before it is sent.
  rehearsal_state_.update_task({{"task_id", "r1"}, {"state", "SUCCEEDED"}});
  r = post("/api/planner/rehearse", kLocalize, kAda);
  ASSERT_EQ(r->status, 409) << r->body;
  EXPECT_NE(body(r)["error"].get<std::string>().find("new task id"), std::string::npos);
  EXPECT_EQ(backend_.actions().size(), 1u);
  const auto audit = audit_entries(dir_ + "/audit.log");
  // The 503, the 409 by the controller, the 409 by the world model, the rehearsal, the refused repeat.
  ASSERT_EQ(audit.size(), 5u);
  EXPECT_EQ(audit[3]["user"], "ada");
  EXPECT_EQ(audit[3]["action"], "rehearse");
  EXPECT_EQ(audit[3]["target"], "r1");
  EXPECT_EQ(audit[3]["result"], "sent to rehearsal domain 7");
  EXPECT_NE(audit[1]["result"].get<std::string>().find("refused"), std::string::npos);
  EXPECT_NE(audit[2]["result"].get<std::string>().find("refused: the rehearsal world model refused"),
            std::string::npos);
}

// No controller yet, a start command configured: 202, nothing sent, the start journaled with who; the
// page follows /api/rehearsal/cell.
TEST_F(HttpApiRehearsalTest, RehearseStartingTheRehearsalCellAnswers202AndSendsNothing) {
  backend_.rehearse_answer_ = {
      false, "starting", {{"starting", true}, {"started", true}, {"cell", {{"phase", "starting"}, {"log", "/tmp/cell.log"}}}}};
  auto r = post("/api/planner/rehearse", kLocalize, kAda);
  ASSERT_EQ(r->status, 202) << r->body;
  EXPECT_EQ(body(r)["starting"], true);
  EXPECT_EQ(body(r)["cell"]["log"], "/tmp/cell.log");
  EXPECT_TRUE(backend_.actions().empty());
  const auto audit = audit_entries(dir_ + "/audit.log");
  ASSERT_EQ(audit.size(), 1u);
  EXPECT_EQ(audit[0]["user"], "ada");
  EXPECT_NE(audit[0]["result"].get<std::string>().find("started the rehearsal cell"), std::string::npos) << audit[0];
  r = client_->Get("/api/rehearsal/cell", as(kVic));
  ASSERT_EQ(r->status, 200) << r->body;
  EXPECT_EQ(body(r)["phase"], "starting");
}

TEST_F(HttpApiRehearsalTest, TheRehearsalsStateAndStreamAreItsOwnNotTheCells) {
  state_.update_task({{"task_id", "cell-task"}, {"state", "RUNNING"}});
  rehearsal_state_.update_task({{"task_id", "r1"}, {"state", "RUNNING"}});
  rehearsal_state_.update_node({{"task_id", "r1"}, {"node_id", "/root"}, {"state", "RUNNING"}});
  auto r = client_->Get("/api/rehearsal/state", as(kVic));
  ASSERT_EQ(r->status, 200);
  EXPECT_EQ(body(r)["domain"], 7);
  ASSERT_EQ(body(r)["tasks"].size(), 1u);
  EXPECT_EQ(body(r)["tasks"][0]["task_id"], "r1");
  EXPECT_EQ(body(r)["nodes"]["r1"][0]["node_id"], "/root");
  r = client_->Get("/api/state", as(kVic));
  ASSERT_EQ(body(r)["tasks"].size(), 1u);
  EXPECT_EQ(body(r)["tasks"][0]["task_id"], "cell-task");
  // The stream from the beginning of the rehearsal's log: its two events, then (nothing more) it is cut.
  std::string received;
  httplib::Client stream("127.0.0.1", api_->port());
  stream.set_read_timeout(1, 0);
  stream.Get(("/api/rehearsal/events?token=" + created_[kVic].token + "&last_event_id=42:0").c_str(),
             [&](const char* data, std::size_t n) {
               received.append(data, n);
               return received.find("event: node") == std::string::npos;
             });
  EXPECT_NE(received.find("event: task"), std::string::npos) << received;
  EXPECT_NE(received.find("\"r1\""), std::string::npos) << received;
  EXPECT_EQ(received.find("cell-task"), std::string::npos) << received;
}

}  // namespace
}  // namespace rigger::console::testing
