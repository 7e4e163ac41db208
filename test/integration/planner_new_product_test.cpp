// A new product in the Planner (docs/console.md, "Your own product"): two STEP files the repository does not
// ship, written here with OpenCascade before any service starts (rigger::sim::write_new_product: an L bracket
// with two through holes, a base plate with six holes of two diameters on a pattern that is not a rectangle
// and a marker tab), become the paper's task in a real browser (planner/new_product.mjs) against the real CAD
// service, world model, task controller and console, with scripted executors announcing the real skill library
// on a private DDS domain. Through the page only: imported, added to the cell, the plate placed on the target by picks,
// the features declared by picks (each a confirmed cell revision), the paper's tree shape built by clicks,
// validated, exported and published; no coordinate typed (the page's count says which fields were typed).
// This test checks what the system made of it, against the geometry it wrote:
//  - the world model serves the plate where the picks put it (its bottom face on the target's top face) and
//    its six screw holes where the file has them, each with the screw type and torque of its pattern;
//  - the bracket's grasp, approach (100 mm out), rope attachment (at its hole), marker and its insertion
//    (its bottom face on the plate's top face, a hole of each lined up by the pin) are served as the picks
//    made them; the two markers' ids are the lowest no object carried (the page proposed them);
//  - the session met the goal for the paper's task on a new product: at most 120 clicks and 10 typed values;
//  - the exported recipe is canonical, names the planned objects and features and screws the six holes with the
//    world model's per-hole torques;
//  - the script itself checked that the session, replayed in a new page on the cell rolled back to where it
//    started, exported the same recipe and made the same cell document, byte for byte.
//  - the bracket, given a sling above its centre of mass, took the crane's rope from the shipped load: it hangs
//    where the load hung (its sling under the hook, its bottom as high as the load's was) and the load stands
//    on the floor where the bracket stood;
//  - Rehearse, clicked on the new product's plan, made the console start its rehearsal cell on a second
//    domain on the new product's revision, as deployed (deploy/config/console.json: rigger-compose supervise on
//    deploy/compose.yaml, every service of the simulated cell: physics, crane gateway, tracker on the
//    rendered camera, admittance, the real skill executors, the scripted operator): that world model ran the
//    revision's document (its sha256) before the controller gave the rehearsed task a status, the page showed
//    it SUCCEEDED, and by the simulator's ground truth the bracket was within 5 mm / 1 degree of its CAD
//    insertion pose on the plate when the Release started (screwed on; after it the bracket hangs again);
//  - Publish ran the task in physics on the console's own cell: programmed with only what programming needs
//    (scripted executors announcing the library), that cell becomes the simulated cell once the rehearsal cell
//    has stopped (its services left their domain; two cells in physics do not keep up on two cores): the
//    scripted executors stop and every other service of deploy/compose.yaml starts beside the world model and
//    the controller, cell_sim on the world model's running revision (the session's document, written with its
//    models as the console writes it for its rehearsal cell); the page publishes once the console offers the
//    skills of exactly the cell's executors. The task ran to SUCCEEDED with the bracket, by the simulator's
//    ground truth when the Release started, within 5 mm / 1 degree of the insertion the cell file's CAD gives.
#include <algorithm>
#include <cmath>
#include <deque>
#include <filesystem>
#include <fstream>
#include <map>
#include <memory>
#include <set>
#include <vector>

#include <Eigen/Geometry>
#include <nlohmann/json.hpp>

#include "planner_test_support.hpp"
#include "rehearsal_cell_file.hpp"
#include "rigger/protocol/task.hpp"
#include "rigger/protocol/sim.hpp"
#include "rigger/protocol/task_names.hpp"
#include "rigger/protocol/world.hpp"
#include "rigger/sim/generated_cell.hpp"
#include "rigger/testing/require.hpp"
#include "rigger/dds/conversions.hpp"
#include "rigger/world_protocol/cell_protocol.hpp"
#include "scenario_support.hpp"

namespace rigger::testing {
namespace {

using namespace std::chrono_literals;
using nlohmann::json;

Eigen::Vector3d vec(const json& a) {
  return {a.at(0).get<double>(), a.at(1).get<double>(), a.at(2).get<double>()};
}

/// The pose of a world-model entity answer (world_pose, else pose; a quaternion, rotation rows or rpy_deg).
Eigen::Isometry3d pose_of(const json& entity) {
  const json& p = entity.contains("world_pose") ? entity.at("world_pose") : entity.at("pose");
  Eigen::Isometry3d t = Eigen::Isometry3d::Identity();
  t.translation() = vec(p.at("position_m"));
  if (p.contains("quaternion_xyzw")) {
    const json& q = p.at("quaternion_xyzw");
    t.linear() = Eigen::Quaterniond(q.at(3).get<double>(), q.at(0).get<double>(), q.at(1).get<double>(), q.at(2).get<double>())
                     .normalized()
                     .toRotationMatrix();
  } else if (p.contains("rotation")) {
    for (int i = 0; i < 3; ++i) t.linear().row(i) = vec(p.at("rotation").at(i)).transpose();
  } else {
    const Eigen::Vector3d rpy = vec(p.at("rpy_deg")) * M_PI / 180.0;
    t.linear() = (Eigen::AngleAxisd(rpy.z(), Eigen::Vector3d::UnitZ()) *
                  Eigen::AngleAxisd(rpy.y(), Eigen::Vector3d::UnitY()) *
                  Eigen::AngleAxisd(rpy.x(), Eigen::Vector3d::UnitX()))
                     .toRotationMatrix();
  }
  return t;
}

/// The last lines of each log of the rehearsal cell's services (rigger-compose writes them beside its own).
std::string compose_logs(std::uint32_t domain) {
  std::string out;
  const std::filesystem::path dir = "/tmp/rigger-compose/" + std::to_string(domain);
  std::error_code none;
  for (const auto& file : std::filesystem::directory_iterator(dir, none)) {
    std::ifstream in(file.path());
    std::deque<std::string> tail;
    for (std::string line; std::getline(in, line);) {
      tail.push_back(line);
      if (tail.size() > 25) tail.pop_front();
    }
    out += "===== " + file.path().string() + "\n";
    for (const auto& line : tail) out += line + "\n";
  }
  return out;
}

/// Distance (m) and angle (degrees) between two poses.
std::pair<double, double> pose_error(const Eigen::Isometry3d& goal, const Eigen::Isometry3d& pose) {
  return {(goal.translation() - pose.translation()).norm(),
          Eigen::AngleAxisd(goal.linear() * pose.linear().transpose()).angle() * 180.0 / M_PI};
}

/// The physics of the rehearsal domain: the simulator's ground truth of each object over the last 2 s, and
/// the truth of the bracket and the plate when each node (by name) last started running.
class RehearsalTruth {
 public:
  explicit RehearsalTruth(Cell& cell)
      : truth_(cell.participant(), protocol::sim::kGroundTruth),
        nodes_(cell.participant(), protocol::task::kNodeStatus, dds::qos::state_changes()) {
    cell.loop().on_data(truth_, [this] {
      truth_.take([this](const rigger_vision_TrackedPose& p, const dds_sample_info_t&) {
        auto& history = history_[dds::to_string(p.object_id)];
        history.emplace_back(dds::to_domain(p.header.stamp), dds::to_domain(p.pose.pose));
        if (history.size() > 100) history.pop_front();
      });
    });
    cell.loop().on_data(nodes_, [this] {
      nodes_.take([this](const rigger_task_NodeStatus& s, const dds_sample_info_t&) {
        const std::string name = dds::to_string(s.name);
        states_[name] = s.state;
        const auto bracket = at("bracket", dds::to_domain(s.started));
        const auto plate = at("base_plate", dds::to_domain(s.started));
        if (s.state == rigger_task_NODE_RUNNING && bracket && plate) started_[name] = {*bracket, *plate};
      });
    });
  }
  /// The bracket's and the plate's true poses when node `name` last started, if the truth then was seen.
  std::optional<std::pair<Eigen::Isometry3d, Eigen::Isometry3d>> at_start(const std::string& name) const {
    const auto it = started_.find(name);
    return it == started_.end() ? std::nullopt : std::optional(it->second);
  }
  std::string nodes() const {
    std::string out;
    for (const auto& [name, state] : states_) out += name + ": " + protocol::task::node_state_name(state) + "\n";
    return out;
  }

 private:
  // The latest sample stamped at or before `t`, at most 100 ms before it.
  std::optional<Eigen::Isometry3d> at(const std::string& object, WallTime t) const {
    const auto it = history_.find(object);
    if (it == history_.end()) return std::nullopt;
    for (auto s = it->second.rbegin(); s != it->second.rend(); ++s)
      if (s->first <= t) return t - s->first <= std::chrono::milliseconds(100) ? std::optional(s->second) : std::nullopt;
    return std::nullopt;
  }

  dds::Reader<rigger_vision_TrackedPose> truth_;
  dds::Reader<rigger_task_NodeStatus> nodes_;
  std::map<std::string, std::deque<std::pair<WallTime, Eigen::Isometry3d>>> history_;
  std::map<std::string, int> states_;
  std::map<std::string, std::pair<Eigen::Isometry3d, Eigen::Isometry3d>> started_;
};

/// The bytes of the file at `path`.
std::string file_bytes(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

using PlannerNewProductTest = WithRehearsalCell<PlannerCellTest>;

TEST_F(PlannerNewProductTest, ANewProductImportedPlacedDeclaredAndProgrammedByClicksOnly) {
  RIGGER_REQUIRE_OR_SKIP(browser_tools_present(), "needs /usr/bin/chromium, node and services/console/web/node_modules (deploy/setup runs npm ci)");
  // Every file this test writes is written here, before the cell starts.
  const sim::NewProductModels models = sim::write_new_product(cell_.log_dir() + "/new-product");
  // The console's cell: its world model's running revision (the latest kept), which the published run's
  // physics starts on.
  std::optional<world_protocol::CellRevision> running;
  dds::Reader<rigger_world_CellRevision> running_revisions(cell_.participant(), protocol::world::kCell);
  const auto take_running = [&] {
    running_revisions.take([&](const rigger_world_CellRevision& w, const dds_sample_info_t&) {
      if (!running || w.cell_revision >= running->cell_revision) running = world_protocol::from_wire(w);
    });
  };
  cell_.loop().on_data(running_revisions, take_running);
  // The rehearsal cell the console starts on demand, on the revision it rehearses: the deployment's start
  // (deploy/config/console.json), its PLC port free and its state in the test's folder.
  std::filesystem::create_directories(rehearsal_.log_dir());
  const json rehearsal = {
      {"start", json::array({bin_dir() + "/rigger-compose", "--file", repo_file("deploy/compose.yaml"), "supervise",
                             "--in-group", "task_controller", "scripted_operator"})},
      {"env", json::array({"RIGGER_PLC_PORT=" + std::to_string(free_tcp_port()), "RIGGER_STATE_DIR=" + rehearsal_.log_dir()})},
      {"cell_folder", repo_file("deploy/cell")},
      {"log_file", rehearsal_.log_dir() + "/rehearsal-cell.log"},
      {"idle_stop_s", 3},
      {"start_timeout_s", 180},
      {"stop_timeout_s", 30}};
  RehearsalTruth physics(rehearsal_);
  std::vector<std::string> seen;  // on the rehearsal domain, in order: its world model's revisions, task statuses
  std::string rehearsed;          // the rehearsed task and its latest state
  int rehearsed_state = -1;
  dds::Reader<rigger_world_CellRevision> revisions(rehearsal_.participant(), protocol::world::kCell);
  dds::Reader<rigger_task_TaskStatus> statuses(rehearsal_.participant(), protocol::task::kStatus);
  rehearsal_.loop().on_data(revisions, [&] {
    revisions.take([&](const rigger_world_CellRevision& w, const dds_sample_info_t&) {
      seen.push_back("revision " + world_protocol::from_wire(w).sha256);
    });
  });
  rehearsal_.loop().on_data(statuses, [&] {
    statuses.take(
        [&](const rigger_task_TaskStatus& s, const dds_sample_info_t&) {
          rehearsed = dds::to_string(s.task_id);
          rehearsed_state = s.state;
          seen.push_back("task " + rehearsed);
        });
  });
  ASSERT_TRUE(start_planner_services(
      {{"rehearsal_domain", rehearsal_.domain_id()}, {"rehearsal", rehearsal}}));
  const std::string result_file = cell_.log_dir() + "/new-product-result.json";
  // The script publishes once the console offers the skills of exactly these executors: the cell's own.
  BrowserScript script = start_browser_script(
      "test/integration/planner/new_product.mjs", result_file,
      {{"BRACKET", models.bracket.string()},
       {"PLATE", models.plate.string()},
       {"CELL_EXECUTORS", "monitors,operator-skills,perception-skills,robot-skills"}},
      {&rehearsal_, &cell_});
  // Rehearsed, and the rehearsal cell stopped (idle): its every service left its domain. Two cells in physics
  // at once do not keep up on two cores.
  const auto rehearsal_over = [&] {
    const auto& services = rehearsal_.directory().services();
    return scenario::task_terminal(rehearsed_state) && !services.empty() &&
           std::none_of(services.begin(), services.end(), [](const auto& s) { return s.second.alive; });
  };
  ASSERT_TRUE(rehearsal_.wait_until([&] { return *script.ended || rehearsal_over(); }, std::chrono::minutes(8)))
      << "the rehearsal did not end, or its cell did not stop\n"
      << physics.nodes() << compose_logs(rehearsal_.domain_id());
  // Then the console's cell in physics: its scripted executors replaced by every other service of the
  // simulated cell, cell_sim on the world model's running revision (written as the console writes it for its
  // rehearsal cell, the new product's models from the files written above).
  std::optional<console::RehearsalCellFiles> cell_files;
  std::unique_ptr<scenario::ScenarioCell> physics_cell;
  const auto t_swap = std::chrono::steady_clock::now();
  if (!*script.ended) {
    for (const char* scripted : {"skills", "monitors"}) {
      const auto stopped = cell_.stop(scripted, SIGINT, 10s);
      ASSERT_TRUE(stopped && stopped->ok()) << scripted << " did not stop cleanly";
    }
    take_running();  // what came while the rehearsal domain's loop ran
    ASSERT_TRUE(running.has_value()) << "no running revision on the console's domain";
    cell_files.emplace(repo_file("deploy/cell"), cell_.log_dir() + "/published-cell");
    std::vector<world_protocol::CellModel> steps;
    for (const auto& file : {models.bracket, models.plate})
      steps.push_back({"", file.filename().string(), file_bytes(file)});
    const std::string cell_file =
        cell_files->write({running->cell_revision, running->sha256, running->cell_json, steps}).string();
    physics_cell = scenario::ScenarioCell::beside_controller(cell_, {cell_file, "bracket", "base_plate"});
    ASSERT_TRUE(physics_cell->ready()) << "the console's cell did not come up in physics";
    physics_cell->watch(rehearsed);
  }
  const double swap_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t_swap).count();
  ASSERT_TRUE(finish_browser_script(script, cell_, std::chrono::minutes(5)))
      << physics.nodes() << compose_logs(rehearsal_.domain_id());
  std::ifstream in(result_file);
  const json result = json::parse(in);
  const json& world = result.at("world");

  // The plate: its bottom face (z = -0.03 m in its frame) on the target's top face (z = 0 in the target's).
  const Eigen::Isometry3d plate = pose_of(world.at("base_plate"));
  const Eigen::Isometry3d target = pose_of(world.at("target"));
  const Eigen::Vector3d bottom_in_target = target.inverse() * (plate * Eigen::Vector3d(0, 0, -0.03));
  EXPECT_NEAR(bottom_in_target.z(), 0.0, 1e-6) << "the plate's bottom face is not on the target's top face";
  EXPECT_NEAR((plate.linear() * Eigen::Vector3d::UnitZ()).dot(target.linear() * Eigen::Vector3d::UnitZ()), 1.0, 1e-9);

  // Its six holes where the file has them, torque and screw type by pattern: 17.5 mm ones 120 N·m, 14 mm 80.
  const std::map<std::pair<int, int>, std::pair<std::string, double>> expected = {
      {{-150, -120}, {"M20x60", 120}}, {{150, -120}, {"M20x60", 120}}, {{110, 120}, {"M20x60", 120}},
      {{-110, 120}, {"M20x60", 120}},  {{-50, 0}, {"M16x50", 80}},     {{90, 40}, {"M16x50", 80}}};
  const json& holes = world.at("base_plate").at("features").at("screw_holes");
  ASSERT_EQ(holes.size(), 6u) << holes.dump(2);
  std::map<std::string, double> torque_of;
  std::set<std::pair<int, int>> holes_at;
  for (const json& h : holes) {
    const Eigen::Vector3d p = vec(h.at("pose").at("position_m"));
    const std::pair<int, int> mm{static_cast<int>(std::lround(p.x() * 1e3)), static_cast<int>(std::lround(p.y() * 1e3))};
    ASSERT_EQ(expected.count(mm), 1u) << "a hole at " << p.transpose() << " the file does not have: " << h.dump();
    EXPECT_NEAR(p.z(), 0.0, 1e-6) << h.dump();
    EXPECT_EQ(h.at("screw_type"), expected.at(mm).first) << h.dump();
    EXPECT_EQ(h.at("torque_nm").get<double>(), expected.at(mm).second) << h.dump();
    torque_of["base_plate/" + h.at("id").get<std::string>()] = h.at("torque_nm").get<double>();
    holes_at.insert(mm);
  }
  EXPECT_EQ(holes_at.size(), 6u) << "two holes declared at one place";

  // The bracket's features as the picks made them.
  const json& bracket = world.at("bracket").at("features");
  const auto frame_of = [&](const char* list, const char* id) -> json {
    for (const json& f : bracket.at(list))
      if (f.at("id") == id) return f.contains("pose") ? f.at("pose") : f;
    ADD_FAILURE() << "bracket has no " << list << " " << id << ": " << bracket.dump(2);
    return json::object();
  };
  const json grasp = frame_of("grasp_frames", "grasp");
  const json approach = frame_of("approach_waypoints", "pre_grasp");
  ASSERT_TRUE(grasp.contains("position_m") && approach.contains("position_m")) << bracket.dump(2);
  EXPECT_NEAR(vec(grasp.at("position_m")).x(), -0.20, 1e-6) << "the grasp is not on the web's outer face";
  EXPECT_NEAR((vec(approach.at("position_m")) - vec(grasp.at("position_m"))).norm(), 0.10, 1e-6)
      << "the approach is not 100 mm out of the grasp";
  // The sling: 20 mm above the web's top (z 0.33), over the centre of mass of the base plate (less its two
  // holes) and the web: x = (0.0035847 * -0.000256 + 0.0027 * -0.185) / 0.0062847 = -0.0796 m.
  const Eigen::Vector3d rope = vec(bracket.at("rope_attachment").at("position_m"));
  EXPECT_LT((rope - Eigen::Vector3d(-0.0796, 0.0, 0.35)).norm(), 2e-4) << "the sling is not above the centre of mass";
  // Hanging where the shipped load hung (its hook at (3.55, 1.75), its bottom at 1.10 m), level; the load on the
  // floor where the bracket stood.
  const Eigen::Isometry3d hung = pose_of(world.at("bracket"));
  EXPECT_LT(((hung * rope).head<2>() - Eigen::Vector2d(3.55, 1.75)).norm(), 1e-6) << (hung * rope).transpose();
  EXPECT_NEAR(hung.translation().z(), 1.10, 1e-6);
  EXPECT_NEAR((hung.linear() * Eigen::Vector3d::UnitZ()).z(), 1.0, 1e-9);
  EXPECT_NEAR(pose_of(world.at("load")).translation().z(), 0.101, 1e-6) << "the load is not on the floor";
  // Their ids as the page proposed them: the lowest that no object of the cell carries, the plate's two first.
  std::set<int> used;
  const json shipped = json::parse(std::ifstream(repo_file("deploy/cell/simulated_cell.json")));
  for (const json& e : shipped.at("entities"))
    if (e.contains("features") && e.at("features").contains("markers"))
      for (const json& m : e.at("features").at("markers").at("items")) used.insert(m.at("id").get<int>());
  std::vector<int> free_ids;
  for (int id = 0; free_ids.size() < 4; ++id)
    if (used.count(id) == 0) free_ids.push_back(id);
  const auto marker_ids = [&](const char* entity) {
    std::set<int> ids;
    for (const json& m : world.at(entity).at("features").at("markers").at("items")) ids.insert(m.at("id").get<int>());
    return ids;
  };
  EXPECT_EQ(marker_ids("base_plate"), (std::set<int>{free_ids[0], free_ids[1]}));
  EXPECT_EQ(marker_ids("bracket"), (std::set<int>{free_ids[2], free_ids[3]}));
  const json& insertion = bracket.at("insertion");
  EXPECT_EQ(insertion.at("target"), "base_plate");
  // The bracket's bottom face (z = 0) on the plate's top face (z = 0), pinned: its hole at (0.06, -0.09) on the
  // plate's at (0.09, 0.04).
  const Eigen::Isometry3d inserted = pose_of(json{{"pose", insertion.at("pose_in_target")}});
  EXPECT_NEAR(insertion.at("pose_in_target").at("position_m").at(2).get<double>(), 0.0, 1e-6) << insertion.dump(2);
  EXPECT_LT((inserted * Eigen::Vector3d(0.06, -0.09, 0.0) - Eigen::Vector3d(0.09, 0.04, 0.0)).norm(), 1e-6)
      << "the pin does not line the holes up: " << insertion.dump(2);

  // The export: canonical, the planned objects and features, the six holes with the world model's torques.
  const std::string exported = result.at("exported");
  const json recipe = json::parse(exported);
  EXPECT_EQ(exported, recipe.dump(2) + "\n") << "the export is not in canonical form";
  const json& root = recipe.at("root");
  ASSERT_EQ(root.at("children").size(), 6u) << root.dump(2);
  const json attach = root.at(json::json_pointer("/children/2/children/0"));
  EXPECT_EQ(attach.at("params").at("grasp"), "bracket/grasp");
  EXPECT_EQ(attach.at("params").at("approach"), "bracket/pre_grasp");
  const json& screw = root.at("children").at(4);
  ASSERT_EQ(screw.at("skill"), "Screw");
  std::set<std::string> screwed;
  for (const json& h : screw.at("params").at("holes")) screwed.insert(h.get<std::string>());
  EXPECT_EQ(screwed.size(), 6u) << screw.dump(2);
  for (const json& s : screw.at("bindings").at("holes").at("screws")) {
    const std::string feature = s.at("feature");
    ASSERT_EQ(torque_of.count(feature), 1u) << s.dump();
    if (s.contains("torque_nm")) {
      EXPECT_EQ(s.at("torque_nm").get<double>(), torque_of.at(feature)) << s.dump();
    }
  }

  // Rehearsed on the new product's revision: the rehearsal cell's world model ran that document (sha256)
  // before its controller gave the rehearsed task a status.
  std::string order;
  for (const auto& line : seen) order += line + "\n";
  const auto revision_at = std::find(seen.begin(), seen.end(), "revision " + result.at("replay").at("cell").at("sha256").get<std::string>());
  const auto task_at = std::find(seen.begin(), seen.end(), "task " + result.at("rehearsal").at("task_id").get<std::string>());
  ASSERT_NE(revision_at, seen.end()) << "the rehearsal cell never ran the new product's revision\n" << order;
  ASSERT_NE(task_at, seen.end()) << order;
  EXPECT_LT(revision_at, task_at) << order;
  EXPECT_EQ(result.at("rehearsal").at("state"), "SUCCEEDED");
  // In physics: where the bracket was when the Release began (screwed on), against its insertion pose on the
  // plate, both by the simulator's truth.
  const json& release = root.at("children").at(5);
  ASSERT_EQ(release.at("skill"), "Release");
  const auto at_release = physics.at_start(release.value("name", std::string("Release")));
  ASSERT_TRUE(at_release.has_value()) << "the Release never started in physics, or its truth was not seen\n" << physics.nodes();
  const auto [error_m, error_deg] = pose_error(at_release->second * inserted, at_release->first);
  EXPECT_LT(error_m, 0.005) << "the bracket is not where its insertion puts it";
  EXPECT_LT(error_deg, 1.0);
  std::printf("rehearsed in physics in %.1f s (the cell's start included); the bracket screwed on %.1f mm / %.2f deg "
              "from its CAD insertion pose\n",
              result.at("timings_ms").at("rehearsal").get<double>() / 1e3, error_m * 1e3, error_deg);

  // Published: the console's cell, in physics on the revision the session made, ran it to SUCCEEDED with the
  // bracket screwed on where its insertion puts it on the plate (the simulator's truth when the Release
  // started, against the insertion the cell file's CAD gives).
  const std::string task = result.at("published");
  EXPECT_EQ(task, rehearsed) << "the published task is not the rehearsed one";
  EXPECT_EQ(running->sha256, result.at("replay").at("cell").at("sha256").get<std::string>())
      << "the console's cell did not start on the session's revision";
  ASSERT_NE(physics_cell, nullptr) << "the script published before the console's cell was in physics";
  ASSERT_TRUE(physics_cell->wait_task_end(std::chrono::minutes(4))) << "the published task " << task << " did not end";
  EXPECT_EQ(physics_cell->task_state(), rigger_task_TASK_SUCCEEDED) << physics_cell->task_summary();
  const auto published = physics_cell->insertion_error_at_start(release.value("name", std::string("Release")));
  ASSERT_TRUE(published.has_value()) << "the published Release never started, or its truth was not seen";
  EXPECT_LT(published->first, 0.005) << "the published bracket is not where its insertion puts it";
  EXPECT_LT(published->second * 180.0 / M_PI, 1.0);
  std::printf("published: the console's cell up in physics in %.1f s once the rehearsal cell had stopped; from then "
              "to SUCCEEDED %.1f s; the bracket screwed on %.1f mm / %.2f deg from its CAD insertion pose\n%s",
              swap_s, physics_cell->task_seconds(), published->first * 1e3, published->second * 180.0 / M_PI,
              physics_cell->durations().c_str());

  const json& effort = result.at("effort").at("counts");
  std::printf(
      "new product programmed in the browser: %d clicks, %d choices from lists, %d fields typed (%d characters), "
      "%.1f s of session (goal: 120 clicks, 10 typed values); cell revisions %d -> %d; timings (ms) %s; "
      "artifacts in %s\n",
      effort.at("clicks").get<int>(), effort.at("choices").get<int>(), effort.at("fields_typed").get<int>(),
      effort.at("characters").get<int>(), result.at("timings_ms").at("session").get<double>() / 1e3,
      result.at("revision_before").get<int>(), result.at("revision_declared").get<int>(),
      result.at("timings_ms").dump().c_str(), cell_.log_dir().c_str());
  // The goal for the paper's task on a new product: counted actions, the same in every run.
  EXPECT_LE(effort.at("clicks").get<int>(), 120);
  EXPECT_LE(effort.at("fields_typed").get<int>(), 10);
}

}  // namespace
}  // namespace rigger::testing
