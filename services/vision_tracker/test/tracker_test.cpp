#include "tracker.hpp"
#include "sim_support.hpp"

#include <gtest/gtest.h>
#include <Eigen/Eigenvalues>

#include <algorithm>
#include <cmath>

namespace rigger::vision {
namespace {

using std::chrono::milliseconds;

const Stamp kT0 = Stamp(std::chrono::seconds(1700000000));

class TrackerTest : public ::testing::Test {
 protected:
  void SetUp() override {
    scene_ = sim::load_camera_scene(testing::cell_json_path());
    config_ = testing::tracker_config_from_file(testing::cell_json_path());
    poses_ = testing::both_visible_poses(scene_);
    renderer_ = std::make_unique<sim::CameraRenderer>(scene_, testing::render_settings(scene_.camera.noise_stddev));
  }

  cv::Mat frame(const std::vector<sim::ObjectPose>& poses) {
    cv::Mat image;
    renderer_->render(scene_.pose_world_camera, poses, image);
    return image;
  }

  static const ObjectTrack& track_of(const FrameResult& result, const std::string& id) {
    return *std::find_if(result.objects.begin(), result.objects.end(),
                         [&](const ObjectTrack& t) { return t.object_id == id; });
  }

  sim::CameraScene scene_;
  TrackerConfig config_;
  std::vector<sim::ObjectPose> poses_;
  std::unique_ptr<sim::CameraRenderer> renderer_;
};

TEST_F(TrackerTest, ReportsBothObjectsInTheWorldFrame) {
  Tracker tracker(config_);
  const FrameResult result = tracker.process(frame(poses_), kT0);
  ASSERT_EQ(result.status, FrameStatus::kOk);
  ASSERT_EQ(result.objects.size(), 2u);
  EXPECT_TRUE(result.searched_full_frame);
  EXPECT_EQ(result.markers_detected, 4);
  for (std::size_t i = 0; i < 2; ++i) {
    const ObjectTrack& track = result.objects[i];
    EXPECT_EQ(track.object_id, poses_[i].object_id);
    EXPECT_TRUE(track.detected);
    EXPECT_TRUE(track.localized);
    EXPECT_TRUE(track.has_pose);
    EXPECT_EQ(track.stamp, kT0);
    EXPECT_EQ(track.estimate_status, EstimateStatus::kOk);
    EXPECT_EQ(track.markers_used, 2);
    EXPECT_GT(track.quality, 0.9);
    EXPECT_LT(track.reprojection_rms_px, 0.2);
    EXPECT_LT(testing::translation_error_m(track.pose_world_object, poses_[i].pose_world_object), 0.002);
    EXPECT_LT(testing::rotation_error_rad(track.pose_world_object, poses_[i].pose_world_object), 0.5 * M_PI / 180.0);
    EXPECT_TRUE((scene_.pose_world_camera * track.pose_camera_object).isApprox(track.pose_world_object, 1e-9));
    const Eigen::SelfAdjointEigenSolver<Eigen::Matrix<double, 6, 6>> eig(track.covariance_world);
    EXPECT_GT(eig.eigenvalues().minCoeff(), 0.0);
    EXPECT_LT(std::sqrt(track.covariance_world(0, 0) + track.covariance_world(1, 1) + track.covariance_world(2, 2)),
              0.005);
  }
}

TEST_F(TrackerTest, LostObjectHasQualityZeroAtOnceAndIsUnlocalizedAfterTheConfiguredAge) {
  config_.lost_after = milliseconds(300);
  config_.detector.reacquire_every_n_frames = 1;  // look for the missing load in every image
  Tracker tracker(config_);
  for (int i = 0; i < 3; ++i) {
    ASSERT_TRUE(track_of(tracker.process(frame(poses_), kT0 + milliseconds(33 * i)), "load").detected);
  }
  const Stamp last_seen = kT0 + milliseconds(66);
  const Eigen::Isometry3d last_pose =
      track_of(tracker.process(frame(poses_), last_seen + milliseconds(1)), "load").pose_world_object;
  const Stamp seen_at = last_seen + milliseconds(1);

  // The load leaves the view (not drawn): lost in the very next image.
  const std::vector<sim::ObjectPose> target_only = {poses_[1]};
  for (int ms = 33; ms <= 330; ms += 33) {
    const FrameResult result = tracker.process(frame(target_only), seen_at + milliseconds(ms));
    const ObjectTrack& load = track_of(result, "load");
    EXPECT_FALSE(load.detected);
    EXPECT_EQ(load.quality, 0.0);
    EXPECT_EQ(load.estimate_status, EstimateStatus::kNoMarkers);
    EXPECT_EQ(load.stamp, seen_at) << "a stale pose keeps the stamp it was measured at";
    EXPECT_TRUE(load.pose_world_object.isApprox(last_pose));
    EXPECT_EQ(load.localized, ms <= 300) << ms << " ms after the last detection";
    EXPECT_TRUE(track_of(result, "target").detected);
    EXPECT_EQ(track_of(result, "target").stamp, seen_at + milliseconds(ms));
  }
  // Back in view: found again at once.
  const FrameResult back = tracker.process(frame(poses_), seen_at + milliseconds(400));
  EXPECT_TRUE(track_of(back, "load").detected);
  EXPECT_TRUE(track_of(back, "load").localized);
  EXPECT_EQ(track_of(back, "load").stamp, seen_at + milliseconds(400));
}

TEST_F(TrackerTest, TheHangingLoadHidesTheTargetInTheScenarioPose) {
  Tracker tracker(config_);
  const FrameResult result = tracker.process(frame(testing::scenario_poses(scene_)), kT0);
  EXPECT_TRUE(track_of(result, "load").detected);
  EXPECT_FALSE(track_of(result, "target").detected);
  EXPECT_FALSE(track_of(result, "target").localized);
  EXPECT_FALSE(track_of(result, "target").has_pose);
  EXPECT_EQ(track_of(result, "target").quality, 0.0);
}

TEST_F(TrackerTest, SearchesAroundTrackedObjectsAndFallsBackToTheFullFrameAtOnce) {
  config_.filter.enabled = false;  // compare single-image estimates with the truth
  Tracker tracker(config_);
  EXPECT_TRUE(tracker.process(frame(poses_), kT0).searched_full_frame);
  std::vector<sim::ObjectPose> moved = poses_;
  moved[0].pose_world_object.translation() += Eigen::Vector3d(0.01, 0.0, -0.005);
  const FrameResult near = tracker.process(frame(moved), kT0 + milliseconds(33));
  EXPECT_FALSE(near.searched_full_frame);
  EXPECT_TRUE(track_of(near, "load").detected);
  EXPECT_TRUE(track_of(near, "target").detected);
  EXPECT_LT(testing::translation_error_m(track_of(near, "load").pose_world_object, moved[0].pose_world_object), 0.002);
  // A jump far outside the search region: found in the same image by the full-frame fallback.
  moved[0].pose_world_object.translation().x() += 0.4;
  const FrameResult jumped = tracker.process(frame(moved), kT0 + milliseconds(66));
  EXPECT_TRUE(jumped.searched_full_frame);
  EXPECT_TRUE(track_of(jumped, "load").detected);
  EXPECT_LT(testing::translation_error_m(track_of(jumped, "load").pose_world_object, moved[0].pose_world_object),
            0.002);
}

TEST_F(TrackerTest, TheFilterRestartsOnAJumpInsteadOfAveragingAcrossIt) {
  Tracker tracker(config_);
  tracker.process(frame(poses_), kT0);
  tracker.process(frame(poses_), kT0 + milliseconds(33));
  std::vector<sim::ObjectPose> moved = poses_;
  moved[0].pose_world_object.translation().x() += 0.2;
  const FrameResult jumped = tracker.process(frame(moved), kT0 + milliseconds(66));
  EXPECT_LT(testing::translation_error_m(track_of(jumped, "load").pose_world_object, moved[0].pose_world_object),
            0.002);
}

TEST_F(TrackerTest, ReacquiresAMissingObjectPeriodically) {
  config_.detector.reacquire_every_n_frames = 3;
  Tracker tracker(config_);
  tracker.process(frame({poses_[0]}), kT0);  // target not in view: frame 1
  bool full_frame_seen = false;
  for (int i = 1; i <= 3; ++i) {
    const FrameResult result = tracker.process(frame({poses_[0]}), kT0 + milliseconds(33 * i));
    EXPECT_EQ(result.searched_full_frame, (i + 1) % 3 == 0) << "frame " << i + 1;
    full_frame_seen = full_frame_seen || result.searched_full_frame;
  }
  EXPECT_TRUE(full_frame_seen);
}

TEST_F(TrackerTest, BadImagesAreRejectedWithoutChangingState) {
  Tracker tracker(config_);
  ASSERT_EQ(tracker.process(frame(poses_), kT0).status, FrameStatus::kOk);
  EXPECT_EQ(tracker.process(cv::Mat(), kT0 + milliseconds(1)).status, FrameStatus::kEmptyImage);
  EXPECT_EQ(tracker.process(cv::Mat(720, 1280, CV_8UC3, cv::Scalar::all(0)), kT0 + milliseconds(2)).status,
            FrameStatus::kWrongEncoding);
  EXPECT_EQ(tracker.process(cv::Mat(480, 640, CV_8UC1, cv::Scalar(0)), kT0 + milliseconds(3)).status,
            FrameStatus::kWrongSize);
  const FrameResult old = tracker.process(frame(poses_), kT0);
  EXPECT_EQ(old.status, FrameStatus::kOutOfOrder);
  EXPECT_TRUE(old.objects.empty());
  // None of those moved the clock: the next good image a millisecond later is accepted.
  const FrameResult next = tracker.process(frame(poses_), kT0 + milliseconds(1));
  EXPECT_EQ(next.status, FrameStatus::kOk);
  EXPECT_TRUE(track_of(next, "load").detected);
}

TEST_F(TrackerTest, TracksAtAppliesTheLostRuleWhenImagesStop) {
  config_.lost_after = milliseconds(500);
  Tracker tracker(config_);
  tracker.process(frame(poses_), kT0);
  for (const ObjectTrack& track : tracker.tracks_at(kT0 + milliseconds(200))) {
    EXPECT_TRUE(track.localized);
    EXPECT_EQ(track.quality, 0.0);
    EXPECT_EQ(track.stamp, kT0);
  }
  for (const ObjectTrack& track : tracker.tracks_at(kT0 + milliseconds(501))) {
    EXPECT_FALSE(track.localized);
  }
  tracker.reset();
  for (const ObjectTrack& track : tracker.tracks_at(kT0)) {
    EXPECT_FALSE(track.has_pose);
    EXPECT_FALSE(track.localized);
  }
}

TEST_F(TrackerTest, FilteringReducesJitterOnAStaticScene) {
  TrackerConfig unfiltered = config_;
  unfiltered.filter.enabled = false;
  Tracker smooth(config_);
  Tracker raw(unfiltered);
  double smooth_sq = 0.0;
  double raw_sq = 0.0;
  for (int i = 0; i < 16; ++i) {
    const cv::Mat image = frame(poses_);
    const Stamp stamp = kT0 + milliseconds(33 * i);
    const ObjectTrack s = track_of(smooth.process(image, stamp), "target");
    const ObjectTrack r = track_of(raw.process(image, stamp), "target");
    if (i >= 4) {
      smooth_sq += std::pow(testing::translation_error_m(s.pose_world_object, poses_[1].pose_world_object), 2);
      raw_sq += std::pow(testing::translation_error_m(r.pose_world_object, poses_[1].pose_world_object), 2);
    }
  }
  EXPECT_LT(smooth_sq, raw_sq);
}

TEST_F(TrackerTest, MarkersOfUnconfiguredObjectsAreIgnored) {
  config_.objects.pop_back();  // track the load only
  Tracker tracker(config_);
  const FrameResult result = tracker.process(frame(poses_), kT0);
  ASSERT_EQ(result.objects.size(), 1u);
  EXPECT_EQ(result.objects[0].object_id, "load");
  EXPECT_TRUE(result.objects[0].detected);
  EXPECT_EQ(result.markers_detected, 4);
}

TEST_F(TrackerTest, ACameraPoseUpdateMovesTheWorldOutputs) {
  Tracker tracker(config_);
  const ObjectTrack before = track_of(tracker.process(frame(poses_), kT0), "target");
  Eigen::Isometry3d shifted = scene_.pose_world_camera;
  shifted.translation().x() += 0.25;
  ASSERT_TRUE(tracker.set_pose_world_camera(shifted));
  const ObjectTrack after = track_of(tracker.process(frame(poses_), kT0 + milliseconds(500)), "target");
  EXPECT_NEAR(after.pose_world_object.translation().x() - before.pose_world_object.translation().x(), 0.25, 0.002);
  Eigen::Isometry3d bad = shifted;
  bad.linear() *= 2.0;
  EXPECT_FALSE(tracker.set_pose_world_camera(bad));
  bad.translation().z() = std::nan("");
  EXPECT_FALSE(tracker.set_pose_world_camera(bad));
}

TEST_F(TrackerTest, InvalidConfigurationIsRefusedAtConstruction) {
  config_.objects[0].markers[0].size_m = -0.08;
  EXPECT_THROW(Tracker{config_}, TrackerConfigError);
}

}  // namespace
}  // namespace rigger::vision
