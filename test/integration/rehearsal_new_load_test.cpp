// A new crane load rehearsed in physics. The console's link to the rehearsal cell (RehearsalLink) with a
// start command — a shell script running a world model and cell_sim on $RIGGER_CELL_FILE (--cell) and a
// task controller on the rehearsal domain — first rehearses on the shipped cell's document: the cell is
// started on it. Then the cell's revision becomes the generated cell (rigger_generated_cell: its L bracket
// of two solids, STEP written by OpenCascade in the test and pinned by sha256, on the crane's rope instead
// of the box `load`): the rehearsal world model takes it, cell_sim refuses it live (it takes the crane's
// load off the rope), and the link restarts the cell on that revision's document, its models as links to
// the bytes it was sent. The second rehearsal is then sent, cell_sim says it runs the revision, and its
// ground truth has the bracket.
#include <signal.h>

#include <filesystem>
#include <fstream>
#include <future>
#include <iterator>
#include <set>

#include <gtest/gtest.h>

#include "cell_sim_test_support.hpp"
#include "rehearsal_link.hpp"
#include "rigger/base/sha256.hpp"
#include "rigger/dds/conversions.hpp"
#include "rigger/protocol/sim.hpp"
#include "rigger/protocol/system.hpp"
#include "rigger/protocol/world.hpp"
#include "rigger/sim/generated_cell.hpp"
#include "rigger/testing/cell.hpp"
#include "rigger/world_protocol/cell_protocol.hpp"

namespace rigger::testing {
namespace {

using namespace std::chrono_literals;
namespace fs = std::filesystem;
using console::ActionResult;

std::string bytes_of(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

class RehearsalNewLoadTest : public ::testing::Test {
 protected:
  RehearsalNewLoadTest() {
    const std::string dir = cell_.log_dir();
    fs::create_directories(dir);
    const auto config = [&](const std::string& name, const nlohmann::json& j) {
      std::ofstream(dir + "/" + name + ".json") << j.dump(2);
      return dir + "/" + name + ".json";
    };
    nlohmann::json sim = nlohmann::json::parse(bytes_of(repo_file("deploy/config/cell_sim.json")));
    sim["cell_file"] = repo_file("deploy/cell/simulated_cell.json");
    sim["camera"]["enabled"] = false;  // the rehearsal's physics is what this test is about
    const std::string world = config("world_model", {{"cell_config", repo_file("deploy/cell/simulated_cell.json")}});
    const std::string controller = config("task_controller", {{"journal_path", dir + "/journal.sqlite"}});
    script_ = dir + "/rehearsal-cell.sh";
    std::ofstream out(script_);
    out << "#!/bin/sh\n# The test's rehearsal cell on $RIGGER_CELL_FILE: world model, physics, controller.\n"
        << bin_dir() << "/world_model --config " << world << " --db " << dir
        << "/world_model.sqlite --cell \"$RIGGER_CELL_FILE\" &\n"
        << bin_dir() << "/cell_sim --config " << config("cell_sim", sim)
        << " --plc-port 0 --cell \"$RIGGER_CELL_FILE\" &\n"
        << bin_dir() << "/task_controller --config " << controller << " &\n"
        << "wait\n";
  }

  /// Publishes `task` on `target` and runs the loop until the link answers.
  ActionResult rehearse(const std::string& task, const console::CellTarget& target) {
    auto promise = std::make_shared<std::promise<ActionResult>>();
    auto answer = promise->get_future();
    link_->publish(task, R"({"task_id": ")" + task + R"(", "root": {"type": "Sequence", "children": []}})",
                   "console:test", target, promise);
    EXPECT_TRUE(cell_.wait_until([&] { return answer.wait_for(0s) == std::future_status::ready; }, 60s)) << task;
    return answer.wait_for(0s) == std::future_status::ready ? answer.get() : ActionResult{false, "no answer", {}};
  }
  /// Runs the loop until the started cell is ready.
  bool ready(std::chrono::seconds timeout) {
    return cell_.wait_until([&] { return link_->cell_status().value("phase", "") == "ready"; }, timeout);
  }

  Cell cell_{"rehearsal"};
  std::string script_;
  std::vector<std::string> journal_;
  std::unique_ptr<console::RehearsalLink> link_;
};

TEST_F(RehearsalNewLoadTest, ANewLoadIsRehearsedOnACellRestartedOnItsRevision) {
  // The shipped cell's document: its models are in the rehearsal cell's own cell folder, unpinned.
  const fs::path shipped = repo_file("deploy/cell/simulated_cell.json");
  const std::string shipped_text = bytes_of(shipped);
  const console::CellTarget first{1, sha256_hex(shipped_text), shipped_text, {}};

  // The new product: the generated cell, every model pinned and sent with the revision, none in a folder
  // the rehearsal cell knows.
  sim::GeneratedCell generated(cell_.log_dir() + "/generated", shipped);
  console::CellTarget second{2, "", "", {}};
  for (auto& entity : generated.document()["entities"]) {
    if (!entity.contains("model") || !entity["model"].contains("step")) continue;
    const std::string name = entity["model"]["step"];
    const std::string step = bytes_of(generated.dir() / name);
    entity["model"]["sha256"] = sha256_hex(step);
    second.models.push_back({sha256_hex(step), name, step});
  }
  second.cell_json = generated.document().dump(2);
  second.sha256 = sha256_hex(second.cell_json);
  ASSERT_FALSE(second.models.empty());

  link_ = std::make_unique<console::RehearsalLink>(
      cell_.domain_id(), cell_.loop(), "test", 20s,
      std::make_pair(console::LaunchCommand{{"/bin/sh", script_}, {}, "", cell_.log_dir() + "/rehearsal-cell.log", ""},
                     console::LaunchTimes{120s, 600s, 20s}),
      [&](const console::CellChange& c, const std::string& who) { journal_.push_back(who + ": " + c.what); },
      shipped.parent_path().string());

  // What the rehearsal domain says: cell_sim's word on its revision, its world model's revision, the truth.
  std::string simulator;
  world_protocol::CellRevision running;
  std::set<std::string> truth;
  dds::Reader<rigger_system_ServiceState> states(cell_.participant(), protocol::system::kServiceState);
  dds::Reader<rigger_world_CellRevision> revisions(cell_.participant(), protocol::world::kCell);
  dds::Reader<rigger_vision_TrackedPose> ground_truth(cell_.participant(), protocol::sim::kGroundTruth);
  cell_.loop().on_data(states, [&] {
    states.take([&](const rigger_system_ServiceState& s, const dds_sample_info_t&) {
      if (dds::to_string(s.kind) == "cell_sim") simulator = dds::to_string(s.detail);
    });
  });
  cell_.loop().on_data(revisions, [&] {
    revisions.take(
        [&](const rigger_world_CellRevision& w, const dds_sample_info_t&) { running = world_protocol::from_wire(w); });
  });
  cell_.loop().on_data(ground_truth, [&] {
    ground_truth.take([&](const rigger_vision_TrackedPose& p, const dds_sample_info_t&) {
      truth.insert(dds::to_string(p.object_id));
    });
  });
  const auto log = [&] { return bytes_of(cell_.log_dir() + "/rehearsal-cell.log"); };

  // Started on the shipped document: its world model's first revision is that file, sha256 and all.
  ActionResult r = rehearse("on-the-box", first);
  ASSERT_TRUE(r.data.value("starting", false)) << r.message;
  ASSERT_TRUE(ready(150s)) << link_->cell_status().dump() << "\n" << log();
  r = rehearse("on-the-box", first);
  EXPECT_FALSE(r.data.value("cell_refused", false)) << r.message << "\n" << log();
  EXPECT_FALSE(r.data.value("starting", false)) << r.message;
  EXPECT_EQ(running.sha256, first.sha256);
  EXPECT_EQ(running.who, "file");
  EXPECT_EQ(simulator, "cell revision " + std::to_string(running.cell_revision));

  // The new load: applied, refused live by cell_sim, the cell restarted on it.
  r = rehearse("on-the-bracket", second);
  ASSERT_TRUE(r.data.value("restarting", false)) << r.message << "\n" << log();
  EXPECT_NE(r.message.find("it takes the crane's load load off the rope for bracket"), std::string::npos) << r.message;
  ASSERT_TRUE(cell_.wait_until([&] { return link_->cell_status().value("phase", "") == "starting"; }, 60s))
      << link_->cell_status().dump();
  truth.clear();  // the old cell is gone: all of its group ended
  ASSERT_TRUE(ready(150s)) << link_->cell_status().dump() << "\n" << log();
  r = rehearse("on-the-bracket", second);
  EXPECT_FALSE(r.data.value("cell_refused", false)) << r.message << "\n" << log();
  EXPECT_FALSE(r.data.value("starting", false)) << r.message;
  EXPECT_EQ(running.sha256, second.sha256);
  EXPECT_EQ(simulator, "cell revision " + std::to_string(running.cell_revision));
  ASSERT_TRUE(cell_.wait_until([&] { return truth.count("bracket") > 0; }, 10s)) << "the physics has no bracket";
  EXPECT_EQ(truth.count("load"), 0u) << "the box is gone with its revision";

  // The journal: started on the first revision, restarted on the second.
  std::string told;
  for (const auto& j : journal_) told += j + "\n";
  EXPECT_NE(told.find("console:test: started (pid"), std::string::npos) << told;
  EXPECT_NE(told.find("on the cell's revision 1"), std::string::npos) << told;
  EXPECT_NE(told.find("to start on the cell's revision 2, which its simulator cannot take live"), std::string::npos)
      << told;
  link_.reset();  // stops the cell, waiting for it
}

}  // namespace
}  // namespace rigger::testing
