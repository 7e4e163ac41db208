// The simulation's real-time factor with every publisher on (target >= 3), next to a bare
// mj_step on the same MJCF measured in the same run. On demand, not a test:
//
//   build/bench/cell_sim_rtf_bench [seconds]
//
// 1. bare mj_step: MuJoCo alone on models/cell.xml (gravity off, no controllers, no PLC, no
//    publishing), measured before and after the process run (the machine is shared);
// 2. the cell_sim process (shipped configuration) unpaced (--real-time-factor 0), with this program
//    subscribed to every topic it publishes, so that every writer has a reader and really sends:
//    wrench 1 kHz, robot state 100 Hz, gripper state, ground truth, status, and 1280x720 images at
//    30 Hz -- all per simulated second. Its real-time factor is simulated time over wall time, read
//    from its own rigger/sim/status (stamped sim_time_s).
#include <arpa/inet.h>
#include <mujoco/mujoco.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <array>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <iostream>
#include <map>
#include <memory>
#include <string>

#include "rigger/dds/conversions.hpp"
#include "rigger/dds/pubsub.hpp"
#include "rigger/performance/results.hpp"
#include "rigger/protocol/robot.hpp"
#include "rigger/protocol/sim.hpp"
#include "rigger/protocol/vision.hpp"
#include "rigger/sim/cell_physics.hpp"
#include "rigger/testing/cell.hpp"

namespace {

using namespace std::chrono_literals;
using Clock = std::chrono::steady_clock;

double bare_mj_step_real_time_factor(double seconds) {
  std::array<char, 1024> error{};
  std::unique_ptr<mjModel, void (*)(mjModel*)> model(
      mj_loadXML(rigger::sim::default_model_path().c_str(), nullptr, error.data(), error.size()), mj_deleteModel);
  if (!model) {
    std::cerr << "cannot load the MJCF: " << error.data() << "\n";
    std::exit(1);
  }
  // As the physics library's own benchmark: gravity off, so that without its controllers the arm does
  // not collapse into contacts; the cost of MuJoCo's step on this model, nothing else.
  model->opt.disableflags |= mjDSBL_GRAVITY;
  std::unique_ptr<mjData, void (*)(mjData*)> data(mj_makeData(model.get()), mj_deleteData);
  std::uint64_t steps = 0;
  const auto t0 = Clock::now();
  while (Clock::now() - t0 < std::chrono::duration<double>(seconds)) {
    for (int i = 0; i < 1000; ++i) mj_step(model.get(), data.get());
    steps += 1000;
  }
  const double wall = std::chrono::duration<double>(Clock::now() - t0).count();
  return static_cast<double>(steps) * model->opt.timestep / wall;
}

/// Counts the samples of one topic, whatever its type.
template <typename T>
struct Counter {
  Counter(rigger::testing::Cell& cell, const rigger::protocol::Topic<T>& topic) : reader(cell.participant(), topic) {
    cell.loop().on_data(reader, [this] { reader.take([this](const T&, const dds_sample_info_t&) { ++count; }); });
  }
  rigger::dds::Reader<T> reader;
  std::uint64_t count = 0;
};

/// A loopback TCP port that is free now (nothing connects to the PLC emulator in this benchmark).
std::uint16_t free_port() {
  const int fd = socket(AF_INET, SOCK_STREAM, 0);
  sockaddr_in addr{};
  addr.sin_family = AF_INET;
  addr.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  socklen_t length = sizeof addr;
  bind(fd, reinterpret_cast<sockaddr*>(&addr), sizeof addr);
  getsockname(fd, reinterpret_cast<sockaddr*>(&addr), &length);
  close(fd);
  return ntohs(addr.sin_port);
}

}  // namespace

int main(int argc, char** argv) {
  const double seconds = argc > 1 ? std::atof(argv[1]) : 5.0;

  const double bare_before = bare_mj_step_real_time_factor(seconds / 2);

  rigger::testing::Cell cell;
  Counter<rigger_sensing_WrenchStamped> wrench(cell, rigger::protocol::robot::kWrench);
  Counter<rigger_robot_RobotState> robot(cell, rigger::protocol::robot::kState);
  Counter<rigger_robot_GripperState> gripper(cell, rigger::protocol::robot::kGripperState);
  Counter<rigger_vision_Image> image(cell, rigger::protocol::vision::kCameraImage);
  Counter<rigger_vision_CameraInfo> info(cell, rigger::protocol::vision::kCameraInfo);
  Counter<rigger_vision_TrackedPose> truth(cell, rigger::protocol::sim::kGroundTruth);
  Counter<rigger_robot_MotionStatus> motion(cell, rigger::protocol::robot::kMotionStatus);
  Counter<rigger_sim_SimEvent> events(cell, rigger::protocol::sim::kEvent);
  rigger::dds::Reader<rigger_sim_SimStatus> status(cell.participant(), rigger::protocol::sim::kStatus);
  struct Point {
    Clock::time_point wall;
    double sim_s;
    std::uint64_t frames;
    std::uint64_t dropped;
  };
  std::vector<Point> points;
  cell.loop().on_data(status, [&] {
    status.take([&](const rigger_sim_SimStatus& s, const dds_sample_info_t&) {
      points.push_back({Clock::now(), s.sim_time_s, s.camera_frames, s.camera_frames_dropped});
    });
  });

  cell.start("cell_sim", "cell_sim",
             {"--config", std::string(RIGGER_SOURCE_DIR) + "/deploy/config/cell_sim.json", "--plc-port",
              std::to_string(free_port()), "--real-time-factor", "0"});
  if (!cell.wait_ready({"cell_sim"}, 30s)) {
    std::cerr << "cell_sim did not start:\n" << cell.logs();
    return 1;
  }
  cell.wait_until([&] { return points.size() > 10; }, 10s);  // discovery done, data flowing
  const std::uint64_t w0 = wrench.count, r0 = robot.count, i0 = image.count, t0 = truth.count;
  const Point first = points.back();
  cell.wait_until([] { return false; },
                  std::chrono::duration_cast<std::chrono::milliseconds>(std::chrono::duration<double>(seconds)));
  const Point last = points.back();
  const auto report = cell.stop_all();
  const double bare_after = bare_mj_step_real_time_factor(seconds / 2);

  const double wall_s = std::chrono::duration<double>(last.wall - first.wall).count();
  const double sim_s = last.sim_s - first.sim_s;
  const double rtf = sim_s / wall_s;
  std::printf("cell_sim real-time factor, every publisher on (%.1f s wall)\n", wall_s);
  std::printf("  bare mj_step on models/cell.xml (same run): %8.1f x real time  (before %.1f, after %.1f)\n",
              (bare_before + bare_after) / 2, bare_before, bare_after);
  std::printf("  cell_sim process, unpaced, all publishers:  %8.1f x real time  (target >= 3)\n", rtf);
  // Best effort, keep-last 1: a reader slower than the writer keeps only the newest sample, so these
  // are what this program managed to take, not what was sent (the writers send every sample).
  std::printf(
      "  taken by this reader per simulated second: wrench %.0f, robot state %.0f, images %.1f, "
      "ground truth %.0f\n",
      (wrench.count - w0) / sim_s, (robot.count - r0) / sim_s, (image.count - i0) / sim_s, (truth.count - t0) / sim_s);
  std::printf("  images rendered per wall second %.1f (dropped while the renderer was busy: %.1f per wall second)\n",
              (last.frames - first.frames) / wall_s, (last.dropped - first.dropped) / wall_s);
  std::printf("  (gripper %llu, camera info %llu, motion %llu, events %llu samples)\n",
              static_cast<unsigned long long>(gripper.count), static_cast<unsigned long long>(info.count),
              static_cast<unsigned long long>(motion.count), static_cast<unsigned long long>(events.count));
  if (!report.ok) {
    std::cerr << report.problems;
    return 1;
  }

  rigger::performance::Report results(
      "cell_sim_rtf_bench", "cell_sim's real-time factor, unpaced, every publisher on and read (" +
                                std::to_string(static_cast<int>(wall_s)) +
                                " s wall), next to a bare mj_step on models/cell.xml measured before and after");
  results.add({"cell_sim process, all publishers", rtf, "x real time", "bare mj_step", (bare_before + bare_after) / 2});
  results.add({"wrench taken per simulated s", (wrench.count - w0) / sim_s, "1/s", "", 0});
  results.add({"robot state taken per simulated s", (robot.count - r0) / sim_s, "1/s", "", 0});
  results.add({"images taken per simulated s", (image.count - i0) / sim_s, "1/s", "", 0});
  results.add({"ground truth taken per simulated s", (truth.count - t0) / sim_s, "1/s", "", 0});
  results.add({"images rendered per wall s", (last.frames - first.frames) / wall_s, "1/s", "", 0});
  results.add({"images dropped per wall s", (last.dropped - first.dropped) / wall_s, "1/s", "", 0});
  return rigger::performance::save_for_main(results);
}
