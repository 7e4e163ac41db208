// The paper's scenario without markers, on every real process: the demo cell with no markers on the load and
// the target (deploy/cell/simulated_cell_markerless.json), rendered by cell_sim with MuJoCo and a
// structured-light sensor's depth noise. recipes/examples/crane_insert_markerless.json localizes both by their
// STEP models (Localize, method model) and InsertVisuallyGuided servoes on the vision tracker's model tracking
// (TRACK_CONTINUOUS of an object without markers). The task must SUCCEED with the load screwed on within 5 mm /
// 1 degree of its insertion pose in the physics, every pose of the load and the target the tracker gave must
// come from their models (none from markers), and the servo must have run on them. The camera renders at 5 Hz
// (a depth camera's rate; MuJoCo's depth costs a third of a core at that rate here), so the admittance
// controller takes poses up to 0.5 s old (max_pose_age_s).
#include <algorithm>
#include <cmath>
#include <map>
#include <vector>

#include "rigger/cell_config/cell_file.hpp"
#include "rigger/protocol/vision.hpp"
#include "scenario_support.hpp"

namespace rigger::testing::scenario {
namespace {

/// What the tracker published of one object: poses by model, poses by markers, refusals by model.
struct TrackerSamples {
  int by_model = 0, by_markers = 0, refused = 0;
  std::map<std::string, int> codes;  ///< the refusals' status codes
  std::vector<double> error_mm;      ///< of the poses by model, against the simulator's truth at the image's stamp
};

double percentile(std::vector<double> v, double p) {
  if (v.empty()) return std::nan("");
  std::sort(v.begin(), v.end());
  return v[static_cast<std::size_t>(p * static_cast<double>(v.size() - 1))];
}

class MarkerlessScenarioTest : public MultiProcessTest {};

TEST_F(MarkerlessScenarioTest, CraneInsertByModelSucceedsWithinFiveMillimetresAndOneDegree) {
  ScenarioSetup setup;
  setup.cell_file = repo_file("deploy/cell/simulated_cell_markerless.json");
  const cell::CellFile cell_file = cell::load_cell_file(setup.cell_file);
  for (const std::string id : {"load", "target"}) {
    const cell::CellEntity& entity = cell_file.require(id, "the markerless scenario");
    ASSERT_FALSE(entity.features.markers.has_value()) << id << " has markers in " << setup.cell_file;
    ASSERT_TRUE(entity.model && !entity.model->step.empty()) << id << " has no STEP model";
  }
  setup.patches = {
      {"cell_sim",
       {{"camera",
         {{"renderer", "mujoco"},
          {"rate_hz", 5},
          {"depth_noise", {{"stddev_at_1m_m", 0.001}, {"grazing_deg", 80.0}, {"edge_gap_m", 0.01}}}}}}},
      {"admittance_control", {{"visual_servo", {{"max_pose_age_s", 0.5}}}}},
  };
  // Every pose the tracker gives of the load and the target, from before the services start.
  std::map<std::string, TrackerSamples> samples;
  const ScenarioCell* cell = nullptr;  // set once the services run
  dds::Qos deep = dds::qos::of(protocol::vision::kTrackerPose.qos);
  deep.keep_last(64);  // none overwritten while the test's thread is busy
  dds::Reader<rigger_vision_TrackedPose> poses(cell_.participant(), protocol::vision::kTrackerPose, deep);
  cell_.loop().on_data(poses, [&] {
    poses.take([&](const rigger_vision_TrackedPose& p, const dds_sample_info_t&) {
      TrackerSamples& s = samples[dds::to_string(p.object_id)];
      const std::string status = dds::to_string(p.status);
      if (p.tracked && (status.empty() || p.markers_used > 0)) {
        ++s.by_markers;  // the marker path's samples carry no status, and the markers they used
      } else if (status == "FOUND") {
        ++s.by_model;
        const auto truth = cell ? cell->true_pose_at(dds::to_string(p.object_id), dds::to_domain(p.header.stamp))
                                : std::nullopt;
        if (truth) s.error_mm.push_back((dds::to_domain(p.pose.pose).translation() - truth->translation()).norm() * 1e3);
      } else if (!status.empty()) {
        ++s.refused;
        ++s.codes[status];
      }
    });
  });

  const auto scenario = ScenarioCell::on(cell_, setup);
  ScenarioCell& s = *scenario;
  cell = &s;
  ASSERT_TRUE(s.ready()) << "not every service came up";
  ASSERT_TRUE(s.submit("recipes/examples/crane_insert_markerless.json"));
  ASSERT_TRUE(s.wait_task_end(std::chrono::minutes(4))) << "the task did not end in time: " << s.task_summary();
  print_report(s, "crane insert without markers");
  for (const auto& [id, t] : samples) {
    std::printf("  tracker poses of %s: %d by model, %d by markers, %d refused", id.c_str(), t.by_model, t.by_markers,
                t.refused);
    for (const auto& [code, count] : t.codes) std::printf(" %s %d", code.c_str(), count);
    std::printf("; off the truth p50 %.1f mm, p95 %.1f mm, max %.1f mm (%zu)\n", percentile(t.error_mm, 0.5),
                percentile(t.error_mm, 0.95), percentile(t.error_mm, 1.0), t.error_mm.size());
  }
  ASSERT_EQ(s.task_state(), rigger_task_TASK_SUCCEEDED) << s.task_summary();
  expect_screwed_on(s);
  EXPECT_FALSE(s.gripper_energized()) << "the robot should have let go at the end";
  for (const std::string id : {"load", "target"}) {
    EXPECT_EQ(samples[id].by_markers, 0) << id << " was tracked by markers";
    // Two Localize answers, then the servo's tracking at a few poses per second for its seconds.
    EXPECT_GE(samples[id].by_model, 10) << id << ": the servo did not run on its model's poses";
  }
}

}  // namespace
}  // namespace rigger::testing::scenario
