#include "tracker_config.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <string>

namespace rigger::vision {
namespace {

using ::testing::HasSubstr;

TrackerConfig good_config() {
  TrackerConfig config;
  config.camera = {1280, 720, 1000.0, 1000.0, 640.0, 360.0, {}};
  MarkerPlacement marker;
  marker.id = 1;
  marker.size_m = 0.08;
  config.objects.push_back({"load", {marker}});
  marker.id = 10;
  config.objects.push_back({"target", {marker}});
  return config;
}

std::string error_of(const std::function<void(TrackerConfig&)>& spoil) {
  TrackerConfig config = good_config();
  spoil(config);
  try {
    validate(config);
  } catch (const TrackerConfigError& e) {
    return e.what();
  }
  return "no error";
}

TEST(TrackerConfig, AcceptsAGoodConfiguration) { EXPECT_NO_THROW(validate(good_config())); }

TEST(TrackerConfig, NamesTheBadCameraField) {
  EXPECT_THAT(error_of([](TrackerConfig& c) { c.camera.width_px = 0; }), HasSubstr("camera.width_px"));
  EXPECT_THAT(error_of([](TrackerConfig& c) { c.camera.fy_px = -1.0; }),
              HasSubstr("camera.fy_px: expected a positive"));
  EXPECT_THAT(error_of([](TrackerConfig& c) { c.camera.cx_px = std::nan(""); }), HasSubstr("camera.cx_px"));
  EXPECT_THAT(error_of([](TrackerConfig& c) { c.camera.distortion[2] = INFINITY; }), HasSubstr("camera.distortion[2]"));
  EXPECT_THAT(error_of([](TrackerConfig& c) { c.pose_world_camera.linear() *= 2.0; }), HasSubstr("pose_world_camera"));
}

TEST(TrackerConfig, NamesTheBadLayoutField) {
  EXPECT_THAT(error_of([](TrackerConfig& c) { c.objects.clear(); }), HasSubstr("objects: expected at least one"));
  EXPECT_THAT(error_of([](TrackerConfig& c) { c.objects[1].object_id = "load"; }),
              HasSubstr("objects[0].object_id: expected a unique id ('load' appears twice)"));
  EXPECT_THAT(error_of([](TrackerConfig& c) { c.objects[1].markers.clear(); }), HasSubstr("objects[1].markers"));
  EXPECT_THAT(error_of([](TrackerConfig& c) { c.objects[1].markers[0].size_m = 0.0; }),
              HasSubstr("objects[1].markers[0].size_m: expected a positive size"));
  EXPECT_THAT(error_of([](TrackerConfig& c) { c.objects[1].markers[0].id = 50; }),
              HasSubstr("objects[1].markers[0].id: expected an id in [0, 50)"));
  EXPECT_THAT(error_of([](TrackerConfig& c) { c.objects[1].markers[0].id = 1; }), HasSubstr("1 is also on 'load'"));
  EXPECT_THAT(error_of([](TrackerConfig& c) { c.objects[0].markers[0].pose_object_marker.translation().x() = NAN; }),
              HasSubstr("objects[0].markers[0].pose_object_marker"));
}

TEST(TrackerConfig, NamesTheBadTuningField) {
  EXPECT_THAT(error_of([](TrackerConfig& c) { c.detector.dictionary = 99; }), HasSubstr("detector.dictionary"));
  EXPECT_THAT(error_of([](TrackerConfig& c) { c.detector.reacquire_every_n_frames = 0; }),
              HasSubstr("detector.reacquire_every_n_frames"));
  EXPECT_THAT(error_of([](TrackerConfig& c) { c.estimator.grazing_viewing_angle_deg = 30.0; }),
              HasSubstr("good_viewing_angle_deg"));
  EXPECT_THAT(error_of([](TrackerConfig& c) { c.filter.position_gain = 0.0; }), HasSubstr("filter.position_gain"));
  EXPECT_THAT(error_of([](TrackerConfig& c) { c.filter.velocity_gain = 2.7; }),
              HasSubstr("filter.velocity_gain: expected a value in [0, 4 - 2 * position_gain)"));
  EXPECT_THAT(error_of([](TrackerConfig& c) { c.lost_after = std::chrono::milliseconds(-1); }),
              HasSubstr("lost_after"));
}

}  // namespace
}  // namespace rigger::vision
