// `riggerctl calibrate camera`: one run of the CalibrateCamera skill, submitted to the task controller as a
// one-node recipe and followed like `riggerctl run` (docs/riggerctl.md). The skill writes the camera's pose as a
// cell revision; `requested_by` names this riggerctl's user in it.

#include <chrono>
#include <cstdio>
#include <memory>
#include <string>

#include <nlohmann/json.hpp>

#include "commands.hpp"
#include "task_support.hpp"

namespace rigger::ctl {
namespace {

struct CalibrateOptions {
  std::string camera = "camera";
  std::string robot = "robot";
  int poses = 10;
  double tilt_deg = 15.0;
  double shift_m = 0.05;
  double max_residual_mm = 2.0;
  double max_residual_deg = 0.5;
  double speed_scale = 0.3;
  tasks::RunOptions run;
};

int calibrate_camera(const CommonOptions& common, CalibrateOptions o) {
  const nlohmann::json params = {{"camera", o.camera},
                                 {"robot", o.robot},
                                 {"poses", o.poses},
                                 {"tilt_rad", {{"value", o.tilt_deg}, {"unit", "deg"}}},
                                 {"shift_m", o.shift_m},
                                 {"max_residual_m", {{"value", o.max_residual_mm}, {"unit", "mm"}}},
                                 {"max_residual_rad", {{"value", o.max_residual_deg}, {"unit", "deg"}}},
                                 {"speed_scale", o.speed_scale},
                                 {"requested_by", riggerctl_source()}};
  const std::string task_id = "calibrate-" + o.camera + "-" +
                              std::to_string(std::chrono::duration_cast<std::chrono::seconds>(
                                                 std::chrono::system_clock::now().time_since_epoch())
                                                 .count());
  const nlohmann::json recipe = {
      {"recipe_version", 1},
      {"task_id", task_id},
      {"description", "calibrate the camera " + o.camera + " with the board on " + o.robot + "'s tool"},
      {"root",
       {{"type", "Skill"}, {"name", "calibrate " + o.camera}, {"skill", "CalibrateCamera"}, {"params", params}}}};
  o.run.file = "calibrate camera";
  o.run.recipe_text = recipe.dump(2);
  return tasks::run_recipe(common, o.run);
}

}  // namespace

void add_calibrate_command(CLI::App& app, const CommonOptions& common, int& exit_code) {
  auto* calibrate = app.add_subcommand("calibrate", "Calibrate a device of the cell");
  calibrate->require_subcommand(1);
  auto o = std::make_shared<CalibrateOptions>();
  auto* camera = calibrate->add_subcommand(
      "camera",
      "Find where the camera really is with the calibration board on the robot's tool (the CalibrateCamera skill, "
      "run once through the task controller) and write it as a cell revision. Start with the board in the picture.");
  camera->add_option("--camera", o->camera, "the camera entity (default camera)");
  camera->add_option("--robot", o->robot, "the robot carrying the board (default robot)");
  camera->add_option("--poses", o->poses, "board poses to show (4-24, default 10)");
  camera->add_option("--tilt-deg", o->tilt_deg, "how far each pose turns the board (5-35, default 15)");
  camera->add_option("--shift-m", o->shift_m, "how far each pose moves the board (0-0.15, default 0.05)");
  camera->add_option("--max-residual-mm", o->max_residual_mm, "largest accepted RMS residual in mm (default 2)");
  camera->add_option("--max-residual-deg", o->max_residual_deg, "largest accepted RMS residual in deg (default 0.5)");
  camera->add_option("--speed-scale", o->speed_scale, "fraction of the arm's maximum speed (default 0.3)");
  camera->add_option("--timeout", o->run.timeout_s, "seconds to wait for the run to end (default: no limit)");
  camera->add_option("--match-timeout", o->run.match_timeout_s, "seconds to wait for the task controller (default 10)");
  camera->add_flag("--quiet", o->run.quiet, "print only the result");
  camera->callback([o, &common, &exit_code] { exit_code = calibrate_camera(common, *o); });
}

}  // namespace rigger::ctl
