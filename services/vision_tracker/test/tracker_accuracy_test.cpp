// Tracker accuracy on the simulated camera against ground truth (the acceptance criterion): load and
// target at 1 to 2 m, 1280 x 720, the configured pixel noise; median translation <= 2 mm and
// median rotation <= 0.5 deg for each object. Prints medians and 90th percentiles.

#include "sim_support.hpp"
#include "tracker.hpp"

#include <gtest/gtest.h>

#include <cstdio>
#include <map>
#include <random>

namespace rigger::vision {
namespace {

constexpr int kPoses = 30;
constexpr double kMaxMedianTranslation_m = 0.002;
constexpr double kMaxMedianRotation_deg = 0.5;

struct Errors {
  int markers_missed = 0;
  std::vector<double> translation_mm;
  std::vector<double> rotation_deg;
  std::vector<double> distance_m;
};

class TrackerAccuracyTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() { scene_ = new sim::CameraScene(sim::load_camera_scene(testing::deployed_cell_json_path())); }
  static void TearDownTestSuite() {
    delete scene_;
    scene_ = nullptr;
  }

  /// Renders kPoses random frames and estimates each with a fresh tracker (single-image accuracy,
  /// no temporal filtering or search-region help).
  static std::map<std::string, Errors> run(const DetectorSettings& detector, double noise_stddev, double blur_px) {
    sim::RenderSettings settings = testing::render_settings(noise_stddev);
    settings.blur_sigma_px = blur_px;
    sim::CameraRenderer renderer(*scene_, settings);
    TrackerConfig config = testing::tracker_config_from_file(testing::deployed_cell_json_path());
    config.detector = detector;
    config.detector.dictionary = scene_->dictionary;
    std::mt19937 rng(20240611);
    std::map<std::string, Errors> errors;
    cv::Mat image;
    for (int i = 0; i < kPoses; ++i) {
      const std::vector<sim::ObjectPose> truth = testing::random_visible_poses(renderer, *scene_, rng);
      renderer.render(scene_->pose_world_camera, truth, image);
      Tracker tracker(config);
      const FrameResult result = tracker.process(image, Stamp(std::chrono::seconds(1)));
      EXPECT_EQ(result.status, FrameStatus::kOk);
      for (const sim::ObjectPose& pose : truth) {
        // The acceptance is the crane scenario's objects; the small part of Pick and Place and
        // its table are in the picture, at their configured poses, but not measured here.
        if (pose.object_id != "load" && pose.object_id != "target") continue;
        const auto track = std::find_if(result.objects.begin(), result.objects.end(),
                                        [&](const ObjectTrack& t) { return t.object_id == pose.object_id; });
        EXPECT_NE(track, result.objects.end());
        EXPECT_TRUE(track->detected) << pose.object_id << " in frame " << i;
        if (!track->detected) {
          continue;
        }
        Errors& e = errors[pose.object_id];
        e.markers_missed += 2 - track->markers_used;
        e.translation_mm.push_back(1000.0 *
                                   testing::translation_error_m(track->pose_world_object, pose.pose_world_object));
        e.rotation_deg.push_back(testing::rotation_error_rad(track->pose_world_object, pose.pose_world_object) * 180.0 /
                                 M_PI);
        e.distance_m.push_back((scene_->pose_world_camera.inverse() * pose.pose_world_object).translation().norm());
      }
    }
    return errors;
  }

  /// The acceptance case, computed once for the suite.
  static const std::map<std::string, Errors>& as_configured() {
    static const std::map<std::string, Errors> errors = run(DetectorSettings{}, scene_->camera.noise_stddev, 0.0);
    return errors;
  }

  static void report(const std::string& label, const std::map<std::string, Errors>& errors) {
    for (const auto& [object, e] : errors) {
      std::printf(
          "[accuracy] %-34s %-6s n=%2zu  distance %.2f..%.2f m  translation median %.3f mm p90 %.3f mm  "
          "rotation median %.3f deg p90 %.3f deg  markers missed %d\n",
          label.c_str(), object.c_str(), e.translation_mm.size(), testing::quantile(e.distance_m, 0.0),
          testing::quantile(e.distance_m, 1.0), testing::quantile(e.translation_mm, 0.5),
          testing::quantile(e.translation_mm, 0.9), testing::quantile(e.rotation_deg, 0.5),
          testing::quantile(e.rotation_deg, 0.9), e.markers_missed);
    }
  }

  static void expect_within_acceptance(const std::map<std::string, Errors>& errors) {
    ASSERT_EQ(errors.size(), 2u);
    for (const auto& [object, e] : errors) {
      ASSERT_EQ(static_cast<int>(e.translation_mm.size()), kPoses) << object;
      EXPECT_LE(testing::quantile(e.translation_mm, 0.5), 1000.0 * kMaxMedianTranslation_m) << object;
      EXPECT_LE(testing::quantile(e.rotation_deg, 0.5), kMaxMedianRotation_deg) << object;
    }
  }

  static sim::CameraScene* scene_;
};

sim::CameraScene* TrackerAccuracyTest::scene_ = nullptr;

TEST_F(TrackerAccuracyTest, MedianErrorsWithinTwoMillimetresAndHalfADegree) {
  std::printf("[accuracy] noise %.1f grey levels, 1280x720, %d random poses, single images\n",
              scene_->camera.noise_stddev, kPoses);
  report("as configured", as_configured());
  expect_within_acceptance(as_configured());
  for (const auto& [object, e] : as_configured()) {
    EXPECT_EQ(e.markers_missed, 0) << object << ": every marker is in plain view";
  }
}

TEST_F(TrackerAccuracyTest, StillWithinWithOpticalBlur) {
  // Real lenses blur: the edge fit must not depend on the renderer's sharp edges. (Blur can cost
  // a detection of the target's small markers now and then: counted, not failed.)
  const std::map<std::string, Errors> blurred = run(DetectorSettings{}, scene_->camera.noise_stddev, 1.0);
  report("blur sigma 1 px", blurred);
  expect_within_acceptance(blurred);
}

TEST_F(TrackerAccuracyTest, EdgeRefinementIsWhatMakesTheDifference) {
  // The same frames with corner windows only: reported for comparison; the edge fit must be
  // better on translation for both objects.
  DetectorSettings corners_only;
  corners_only.refine_edges = false;
  const std::map<std::string, Errors> without = run(corners_only, scene_->camera.noise_stddev, 0.0);
  report("corner windows only (no edge fit)", without);
  for (const auto& [object, e] : as_configured()) {
    EXPECT_LT(testing::quantile(e.translation_mm, 0.5), testing::quantile(without.at(object).translation_mm, 0.5))
        << object;
  }
}

}  // namespace
}  // namespace rigger::vision
