// Cell revisions through the real world_model process and the real riggerctl, on the test's own domain:
// apply, history, diff, rollback and a restart that comes back on the latest revision; invalid revisions
// refused with the file and the JSON pointer, the running one untouched; a revision moving an object a
// running skill holds (a real executor announcement) refused until the run ends.
#include <signal.h>

#include <filesystem>
#include <fstream>
#include <iterator>
#include <optional>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "rigger/dds/conversions.hpp"
#include "rigger/dds/pubsub.hpp"
#include "rigger/protocol/skill.hpp"
#include "rigger/protocol/world.hpp"
#include "rigger/skill_protocol/executor_endpoint.hpp"
#include "rigger/testing/cell.hpp"
#include "rigger/world_client/world_client.hpp"
#include "rigger/world_protocol/cell_protocol.hpp"

namespace rigger::testing {
namespace {

using namespace std::chrono_literals;
namespace fs = std::filesystem;
using json = nlohmann::json;
using world_protocol::CellOp;
using world_protocol::CellReply;
using world_protocol::CellRequest;
using world_protocol::CellRevision;

std::string read_text(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

struct CtlOutcome {
  int code = -1;
  std::string output;
};

class CellRevisionTest : public MultiProcessTest {
 protected:
  CellRevisionTest() {
    // A cell folder of the test's own (the document and its models), so that editing it touches nothing else.
    folder_ = fs::path(cell_.log_dir()) / "cell";
    fs::create_directories(folder_);
    const fs::path shipped = fs::path(RIGGER_SOURCE_DIR) / "deploy/cell";
    fs::copy(shipped / "simulated_cell.json", folder_ / "cell.json");
    fs::copy(shipped / "models", folder_ / "models", fs::copy_options::recursive);
    original_ = read_text(folder_ / "cell.json");
    cell_.loop().on_data(revisions_, [this] {
      revisions_.take([this](const rigger_world_CellRevision& wire, const dds_sample_info_t&) {
        latest_ = world_protocol::from_wire(wire);
      });
    });
    cell_.loop().on_data(replies_, [this] {
      replies_.take([this](const rigger_world_CellReply& wire, const dds_sample_info_t&) {
        CellReply r = world_protocol::from_wire(wire);
        if (r.client_id == "cell-test") replies_by_id_[r.request_id] = r;
      });
    });
  }

  void start_world(const std::string& id) {
    cell_.start(id, "world_model",
                {"--id", id, "--cell", (folder_ / "cell.json").string(), "--db", cell_.log_dir() + "/world.sqlite"});
    ASSERT_TRUE(cell_.wait_ready({id}, 60s)) << cell_.logs();
  }

  bool wait_revision(std::uint64_t revision) {
    return cell_.wait_until([&] { return latest_ && latest_->cell_revision == revision; }, 30s);
  }

  // The document with the load moved by dx along x.
  std::string moved_load(double dx) const {
    json doc = json::parse(original_);
    json& position = doc["entities"][5]["pose"]["position_m"];
    position[0] = position[0].get<double>() + dx;
    return doc.dump(2);
  }

  std::string write(const std::string& name, const std::string& text) const {
    const fs::path path = fs::path(cell_.log_dir()) / name;
    std::ofstream(path) << text;
    return path.string();
  }

  CtlOutcome ctl(const std::string& name, const std::vector<std::string>& args) {
    ChildProcess p("riggerctl", args, {{"RIGGER_DOMAIN", std::to_string(cell_.domain_id())}},
                   cell_.log_dir() + "/ctl-" + name + ".out");
    const auto st = p.wait(60s);
    if (!st) ADD_FAILURE() << "riggerctl " << name << " did not finish";
    return {st && st->exited ? st->code : -1, p.log()};
  }

  // One request on the wire, asked again (a full round trip each time) until answered.
  CellReply request(CellRequest r) {
    r.client_id = "cell-test";
    r.request_id = next_request_++;
    r.who = "cell-test";
    EXPECT_TRUE(requests_.wait_for_readers(1, 10s));
    const auto deadline = std::chrono::steady_clock::now() + 30s;
    while (std::chrono::steady_clock::now() < deadline) {
      rigger_world_CellRequest wire{};
      world_protocol::to_wire(r, wire);
      EXPECT_EQ(requests_.write(wire), DDS_RETCODE_OK);
      if (cell_.wait_until([&] { return replies_by_id_.count(r.request_id) > 0; }, 2s))
        return replies_by_id_[r.request_id];
      if (r.op == CellOp::kApply && !r.dry_run) break;  // not a read: asked once
    }
    ADD_FAILURE() << "no cell reply to request " << r.request_id;
    return {};
  }

  double load_x() {
    world_client::WorldClient client(cell_.participant(), cell_.loop(), null_logger(), "cell-test-wc");
    std::optional<world_client::Reply> got;
    client.pose("load", "world", 10s, [&](const world_client::Reply& r) { got = r; });
    EXPECT_TRUE(cell_.wait_until([&] { return got.has_value(); }, 15s));
    return got && got->ok ? got->pose.translation().x() : -1.0;
  }

  fs::path folder_;
  std::string original_;
  dds::Reader<rigger_world_CellRevision> revisions_{cell_.participant(), protocol::world::kCell};
  dds::Writer<rigger_world_CellRequest> requests_{cell_.participant(), protocol::world::kCellRequest};
  dds::Reader<rigger_world_CellReply> replies_{cell_.participant(), protocol::world::kCellReply};
  std::optional<CellRevision> latest_;
  std::map<std::uint64_t, CellReply> replies_by_id_;
  std::uint64_t next_request_ = 1;
};

TEST_F(CellRevisionTest, ApplyHistoryDiffRollbackAndARestartOnTheLatest) {
  start_world("wm-a");
  ASSERT_TRUE(wait_revision(1)) << cell_.logs();
  EXPECT_EQ(latest_->cell_json, original_);  // the file as it is: a follower that runs on it recognises it
  const double x0 = load_x();

  const CtlOutcome applied =
      ctl("apply", {"cell", "apply", write("moved.json", moved_load(0.1)), "--comment", "load 10 cm on"});
  ASSERT_EQ(applied.code, 0) << applied.output;
  EXPECT_NE(applied.output.find("cell revision 2 (previous 1): 1 moved"), std::string::npos) << applied.output;
  EXPECT_NE(applied.output.find("~ load moved 0.1 m"), std::string::npos) << applied.output;
  ASSERT_TRUE(wait_revision(2));
  EXPECT_EQ(latest_->previous_revision, 1U);
  EXPECT_EQ(json::parse(latest_->changes_json)["moved"][0]["id"], "load");
  EXPECT_EQ(latest_->comment, "load 10 cm on");
  EXPECT_EQ(latest_->who.rfind("riggerctl:", 0), 0U) << latest_->who;
  EXPECT_NEAR(load_x(), x0 + 0.1, 1e-9);

  const CtlOutcome history = ctl("history", {"cell", "history"});
  ASSERT_EQ(history.code, 0) << history.output;
  EXPECT_NE(history.output.find("* 2 "), std::string::npos) << history.output;
  EXPECT_NE(history.output.find("  1 "), std::string::npos) << history.output;
  const CtlOutcome diff = ctl("diff", {"cell", "diff", "1", "2"});
  ASSERT_EQ(diff.code, 0) << diff.output;
  EXPECT_NE(diff.output.find("revision 1 -> 2: 1 moved"), std::string::npos) << diff.output;
  const CtlOutcome shown = ctl("show", {"cell", "show", "1"});
  ASSERT_EQ(shown.code, 0);
  EXPECT_EQ(json::parse(shown.output), json::parse(original_));

  const CtlOutcome rolled = ctl("rollback", {"cell", "rollback", "1"});
  ASSERT_EQ(rolled.code, 0) << rolled.output;
  ASSERT_TRUE(wait_revision(3));
  EXPECT_EQ(latest_->cell_json, original_);
  EXPECT_EQ(latest_->comment, "rollback to revision 1");
  EXPECT_NEAR(load_x(), x0, 1e-9);

  ASSERT_TRUE(cell_.stop("wm-a", SIGINT, 20s).has_value());
  latest_.reset();
  start_world("wm-b");
  ASSERT_TRUE(wait_revision(3)) << cell_.logs();  // the history's latest, not a new revision of the file
  const CtlOutcome again = ctl("history-again", {"cell", "history", "--json"});
  ASSERT_EQ(again.code, 0) << again.output;
  EXPECT_EQ(json::parse(again.output)["revisions"].size(), 3U);
  EXPECT_EQ(ctl("unknown", {"cell", "rollback", "42"}).code, 1);
}

TEST_F(CellRevisionTest, AnInvalidRevisionIsRefusedWithFileAndPointerAndChangesNothing) {
  start_world("wm-a");
  ASSERT_TRUE(wait_revision(1)) << cell_.logs();
  const double x0 = load_x();
  const std::string configured = (folder_ / "cell.json").string();
  const auto refused = [&](const std::string& name, const std::function<void(json&)>& edit,
                           const std::string& pointer) {
    json doc = json::parse(moved_load(0.2));
    edit(doc);
    const CtlOutcome out = ctl(name, {"cell", "apply", write(name + ".json", doc.dump(2))});
    EXPECT_EQ(out.code, 1) << out.output;
    EXPECT_NE(out.output.find("INVALID: " + configured + ": " + pointer), std::string::npos) << out.output;
  };
  refused(
      "mass", [](json& d) { d["entities"][5]["model"]["mass_kg"] = 0.0; }, "/entities/5/model/mass_kg");
  refused(
      "step", [](json& d) { d["entities"][8]["model"]["step"] = "models/no_such.step"; }, "/entities/8/model/step");
  // A face reference matching no face of the model (its index gone, its signature nowhere on the model).
  refused(
      "face",
      [](json& d) {
        json& face = d["entities"][5]["features"]["grasp_frames"][0]["cad"]["face"];
        face["index"] = 9999;
        face["signature"]["centroid_m"] = {5.0, 5.0, 5.0};
      },
      "/entities/5/features/grasp_frames/0/cad/face");
  const CtlOutcome broken = ctl("json", {"cell", "apply", write("broken.json", "{\"cell_version\": 1,")});
  EXPECT_EQ(broken.code, 1);
  EXPECT_NE(broken.output.find("INVALID"), std::string::npos) << broken.output;
  EXPECT_EQ(ctl("missing", {"cell", "apply", cell_.log_dir() + "/no-such.json"}).code, 2);
  EXPECT_NEAR(load_x(), x0, 1e-12);
  const CtlOutcome history = ctl("history", {"cell", "history", "--json"});
  EXPECT_EQ(json::parse(history.output)["revisions"].size(), 1U);
  EXPECT_EQ(latest_->cell_revision, 1U);
}

TEST_F(CellRevisionTest, ARevisionMovingAHeldObjectIsRefusedUntilTheRunEnds) {
  start_world("wm-a");
  ASSERT_TRUE(wait_revision(1)) << cell_.logs();
  dds::Writer<rigger_skill_ExecutorAnnouncement> announcer(cell_.participant(), protocol::skill::kExecutors,
                                                           dds::qos::state());
  const std::string executor = "robot-skills", host = "test", library = R"({"library_version":1,"skills":[]})";
  const auto announce = [&](const std::vector<skill_protocol::AnnouncedRun>& runs) {
    rigger_skill_ExecutorAnnouncement a{};
    a.executor_id = dds::wire_string(executor);
    a.host = dds::wire_string(host);
    a.library_json = dds::wire_string(library);
    skill_protocol::WireRuns storage;
    skill_protocol::wire_runs(a, runs, storage);
    ASSERT_EQ(announcer.write(a), DDS_RETCODE_OK);
  };
  const std::vector<skill_protocol::AnnouncedRun> holding{{"t1", "insert", "Insert", {"load", "robot"}, false}};
  announce(holding);
  CellRequest dry;
  dry.op = CellOp::kApply;
  dry.cell_json = moved_load(0.1);
  dry.dry_run = true;
  // Asked (dry run) until the world model has read the announcement: the answer turns HELD_BY_TASK.
  ASSERT_TRUE(cell_.wait_until([&] { return request(dry).code == "HELD_BY_TASK"; }, 20s));
  CellRequest apply = dry;
  apply.dry_run = false;
  const CellReply held = request(apply);
  EXPECT_FALSE(held.ok);
  EXPECT_EQ(held.code, "HELD_BY_TASK");
  EXPECT_NE(held.message.find("\"load\" is held by task t1 node insert"), std::string::npos) << held.message;
  EXPECT_EQ(held.cell_revision, 1U);

  announce({});  // the run ended
  ASSERT_TRUE(cell_.wait_until([&] { return request(dry).ok; }, 20s));
  const CellReply accepted = request(apply);
  EXPECT_TRUE(accepted.ok) << accepted.code << ": " << accepted.message;
  EXPECT_EQ(accepted.cell_revision, 2U);
  ASSERT_TRUE(wait_revision(2));
}

}  // namespace
}  // namespace rigger::testing
