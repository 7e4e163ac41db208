// Markerless localization (the tracker's TRACK_ONCE_MODEL: ModelLocalizer over rigger_perception) next to
// the marker tracker (Tracker, a full-frame search) on the same frames: the demo cell's load
// (deploy/cell/simulated_cell.json) and the generated cell's L bracket (GeneratedCell), each at kPoses poses
// near where it hangs (±5 cm, yaw ±25°, roll and pitch ±3°), rendered by MujocoCamera from the cell's camera
// with its markers and a structured-light sensor's depth noise (1 mm at 1 m, holes past 80° and at 1 cm
// steps). The part is its STEP model's tessellation on a mocap body above a floor. Time per frame on one
// core (this thread pinned, OpenCV single-threaded; rendering is not timed); accuracy against the truth up
// to the part's symmetry; "wrong": found more than 10 mm or 2° off. Markerless twice: from the truth moved
// by 2 cm and 4° (a world-model prior), and with no prior (the global search). Not a test.
// RIGGER_BENCH_VERBOSE=1 prints each refusal's code and detail to stderr, and each pose found: its error in
// the part's frame and the faces the camera sees. RIGGER_BENCH_PART=load (or bracket) runs that part alone.
#include <sched.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <filesystem>
#include <fstream>
#include <map>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include <opencv2/core/utility.hpp>

#include "model_localizer.hpp"
#include "rigger/performance/results.hpp"
#include "rigger/sim/camera_scene.hpp"
#include "rigger/sim/generated_cell.hpp"
#include "rigger/sim/mujoco_camera.hpp"
#include "tracker.hpp"

namespace {

using namespace rigger;
constexpr int kPoses = 50;
constexpr double kWrongM = 0.010;
constexpr double kWrongDeg = 2.0;

struct ModelDeleter {
  void operator()(mjModel* m) const { mj_deleteModel(m); }
};
struct DataDeleter {
  void operator()(mjData* d) const { mj_deleteData(d); }
};

/// A floor and the part's mesh on a mocap body named `id` (the markers are drawn on the body of that name).
std::unique_ptr<mjModel, ModelDeleter> scene_model(const std::string& id, const perception::Mesh& mesh) {
  std::ostringstream xml;
  xml.precision(9);
  xml << "<mujoco><compiler inertiafromgeom='false'/><visual><headlight ambient='0.35 0.35 0.35' "
         "diffuse='0.55 0.55 0.55' specular='0 0 0'/><map znear='0.01' zfar='20'/></visual><asset><mesh name='part' vertex='";
  for (const Eigen::Vector3d& v : mesh.vertices_m) xml << v.x() << ' ' << v.y() << ' ' << v.z() << ' ';
  xml << "' face='";
  for (const Eigen::Vector3i& t : mesh.triangles) xml << t.x() << ' ' << t.y() << ' ' << t.z() << ' ';
  xml << "'/></asset><worldbody><geom type='plane' size='20 20 0.1' rgba='0.5 0.5 0.5 1'/>"
      << "<body name='" << id << "' mocap='true'><geom type='mesh' mesh='part' contype='0' conaffinity='0' "
      << "rgba='0.8 0.8 0.8 1'/></body></worldbody></mujoco>";
  const std::filesystem::path path =
      std::filesystem::temp_directory_path() / ("rigger_bench_markerless_" + std::to_string(::getpid()) + ".xml");
  std::ofstream(path) << xml.str();
  char error[1000] = "";
  mjModel* model = mj_loadXML(path.c_str(), nullptr, error, sizeof error);
  std::filesystem::remove(path);
  if (model == nullptr) throw std::runtime_error(std::string("MJCF: ") + error);
  return std::unique_ptr<mjModel, ModelDeleter>(model);
}

double angle_deg(const Eigen::Matrix3d& a, const Eigen::Matrix3d& b) {
  return Eigen::AngleAxisd(a.transpose() * b).angle() * 180.0 / M_PI;
}

/// The rotation from the truth to the pose found (nearest symmetric equivalent), as a rotation vector in
/// the part's frame, degrees.
Eigen::Vector3d rotation_error_deg(const Eigen::Matrix3d& found, const Eigen::Matrix3d& truth,
                                   const std::vector<Eigen::Matrix3d>& symmetries) {
  Eigen::Vector3d best = Eigen::Vector3d::Constant(1e9);
  for (const Eigen::Matrix3d& s : symmetries) {
    const Eigen::AngleAxisd d(truth.transpose() * found * s);
    if (d.angle() < best.norm() * M_PI / 180.0) best = d.axis() * d.angle() * 180.0 / M_PI;
  }
  return best;
}

/// The part's faces (its frame's axes) and the angle the camera sees each at, for faces within 85 degrees.
std::string faces_seen(const Eigen::Isometry3d& truth, const Eigen::Isometry3d& camera) {
  const Eigen::Vector3d view = (camera.translation() - truth.translation()).normalized();
  std::string out = "faces seen at";
  const char* names[] = {"+x", "-x", "+y", "-y", "+z", "-z"};
  for (int f = 0; f < 6; ++f) {
    const Eigen::Vector3d n = (f % 2 == 0 ? 1.0 : -1.0) * truth.linear().col(f / 2);
    const double deg = std::acos(std::clamp(n.dot(view), -1.0, 1.0)) * 180.0 / M_PI;
    if (deg < 85.0) out += " " + std::string(names[f]) + " " + std::to_string(static_cast<int>(std::lround(deg)));
  }
  return out;
}

double percentile(std::vector<double> v, double p) {
  if (v.empty()) return NAN;
  std::sort(v.begin(), v.end());
  return v[std::min(v.size() - 1, static_cast<std::size_t>(p * static_cast<double>(v.size())))];
}

struct Tally {
  int found = 0;
  int wrong = 0;
  std::map<std::string, int> refused;
  std::vector<double> position_mm, rotation_deg, time_ms;

  void add(bool ok, const std::string& why, const Eigen::Isometry3d& pose, const Eigen::Isometry3d& truth,
           const std::vector<Eigen::Matrix3d>& symmetries, double ms) {
    time_ms.push_back(ms);
    if (!ok) {
      ++refused[why];
      return;
    }
    ++found;
    double rotation = 1e9;
    for (const Eigen::Matrix3d& s : symmetries) rotation = std::min(rotation, angle_deg(pose.linear() * s, truth.linear()));
    const double position = (pose.translation() - truth.translation()).norm();
    if (position > kWrongM || rotation > kWrongDeg) ++wrong;
    position_mm.push_back(position * 1e3);
    rotation_deg.push_back(rotation);
  }
  void print(const std::string& part, const std::string& method) const {
    std::string why;
    for (const auto& [code, n] : refused) why += code + " " + std::to_string(n) + " ";
    std::printf("| %-8s | %-22s | %2d/%d | %d | %5.2f / %5.2f mm | %5.2f / %5.2f deg | %6.1f / %6.1f ms | %s|\n",
                part.c_str(), method.c_str(), found, kPoses, wrong, percentile(position_mm, 0.5),
                percentile(position_mm, 0.95), percentile(rotation_deg, 0.5), percentile(rotation_deg, 0.95),
                percentile(time_ms, 0.5), percentile(time_ms, 0.99), why.c_str());
  }
};

struct PartFigures {
  Tally markers, prior, tracking, global;
};

PartFigures run_part(const std::string& name, const std::filesystem::path& cell_json, const std::string& id) {
  const cell::CellFile file = cell::load_cell_file(cell_json);
  vision::ModelLocalizer localizer;
  localizer.set_cell(file, cell::cell_model_folder(cell_json));
  std::string problem;
  const perception::Mesh* mesh = localizer.mesh(id, problem);
  if (mesh == nullptr) throw std::runtime_error(problem);
  const std::vector<Eigen::Matrix3d> symmetries = perception::Localizer(*mesh).symmetries();
  vision::Tracker tracker(vision::tracker_config_from_cell(file, "camera"));

  const sim::CameraScene scene = sim::load_camera_scene(cell_json);
  std::vector<sim::BoxObject> objects;
  for (const auto* list : {&scene.objects, &scene.mesh_objects})
    for (const sim::BoxObject& o : *list)
      if (o.id == id) objects.push_back(o);
  const auto model = scene_model(id, *mesh);
  std::unique_ptr<mjData, DataDeleter> data(mj_makeData(model.get()));
  sim::MujocoCameraSettings settings;
  settings.depth_noise.stddev_at_1m_m = 0.001;
  settings.depth_noise.grazing_deg = 80.0;
  settings.depth_noise.edge_gap_m = 0.01;
  sim::MujocoCamera camera(*model, scene.camera, objects, scene.dictionary, settings);

  // Timed work on this thread alone, on one core (the renderer's threads, made above, keep theirs).
  cpu_set_t one;
  CPU_ZERO(&one);
  CPU_SET(0, &one);
  sched_setaffinity(0, sizeof one, &one);
  cv::setNumThreads(1);

  const Eigen::Isometry3d nominal = file.pose_root_entity(id);
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  PartFigures figures;
  auto stamp = std::chrono::system_clock::now();
  for (int i = 0; i < kPoses; ++i) {
    Eigen::Isometry3d truth = nominal;
    truth.translation() += 0.05 * Eigen::Vector3d(unit(rng), unit(rng), unit(rng));
    truth.linear() = truth.linear() * (Eigen::AngleAxisd(25.0 * M_PI / 180 * unit(rng), Eigen::Vector3d::UnitZ()) *
                                       Eigen::AngleAxisd(3.0 * M_PI / 180 * unit(rng), Eigen::Vector3d::UnitY()) *
                                       Eigen::AngleAxisd(3.0 * M_PI / 180 * unit(rng), Eigen::Vector3d::UnitX()))
                                          .toRotationMatrix();
    const Eigen::Quaterniond q(truth.linear());
    for (int k = 0; k < 3; ++k) data->mocap_pos[k] = truth.translation()[k];
    data->mocap_quat[0] = q.w();
    data->mocap_quat[1] = q.x();
    data->mocap_quat[2] = q.y();
    data->mocap_quat[3] = q.z();
    mj_forward(model.get(), data.get());
    sim::CameraFrame frame;
    camera.render(*data, scene.pose_world_camera, {{id, truth}}, frame, true);

    tracker.reset();  // a TRACK_ONCE searches the whole image
    stamp += std::chrono::milliseconds(33);
    auto start = std::chrono::steady_clock::now();
    const vision::FrameResult marked = tracker.process(frame.image_mono8, stamp);
    const double marker_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
    bool seen = false;
    Eigen::Isometry3d marker_pose = Eigen::Isometry3d::Identity();
    for (const vision::ObjectTrack& t : marked.objects) {
      if (t.object_id == id && t.detected) {
        seen = true;
        marker_pose = t.pose_world_object;
      }
    }
    figures.markers.add(seen, "NOT_DETECTED", marker_pose, truth, {Eigen::Matrix3d::Identity()}, marker_ms);

    perception::DepthFrame depth;
    depth.depth_m = frame.depth_m;
    depth.intrinsics = {scene.camera.fx_px, scene.camera.fy_px, scene.camera.cx_px, scene.camera.cy_px};
    depth.pose_world_camera = scene.pose_world_camera;
    Eigen::Isometry3d prior = truth;
    prior.translation() += 0.02 * Eigen::Vector3d(unit(rng), unit(rng), unit(rng)).normalized();
    prior.linear() = prior.linear() * Eigen::AngleAxisd(4.0 * M_PI / 180, Eigen::Vector3d(unit(rng), unit(rng), unit(rng)).normalized())
                                          .toRotationMatrix();
    for (const bool with_prior : {true, false}) {
      start = std::chrono::steady_clock::now();
      const vision::ModelLocalization r =
          localizer.localize(id, depth, with_prior ? std::optional<Eigen::Isometry3d>(prior) : std::nullopt);
      const double ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
      if (!r.found() && std::getenv("RIGGER_BENCH_VERBOSE")) std::fprintf(stderr, "%s %d %s: %s\n", name.c_str(), i, r.status.c_str(), r.detail.c_str());
      if (r.found() && std::getenv("RIGGER_BENCH_VERBOSE")) {
        const Eigen::Vector3d e = truth.linear().transpose() * (r.pose_world_object.translation() - truth.translation()) * 1e3;
        const Eigen::Vector3d w = rotation_error_deg(r.pose_world_object.linear(), truth.linear(), symmetries);
        std::fprintf(stderr, "%s %d %s found, error in the part's frame (%.1f, %.1f, %.1f) mm, (%.2f, %.2f, %.2f) deg; %s\n",
                     name.c_str(), i, with_prior ? "prior" : "global", e.x(), e.y(), e.z(), w.x(), w.y(), w.z(),
                     faces_seen(truth, scene.pose_world_camera).c_str());
      }
      (with_prior ? figures.prior : figures.global).add(r.found(), r.status, r.pose_world_object, truth, symmetries, ms);
    }
    // TRACK_CONTINUOUS's search: from the prior only, with the tracking's model support.
    start = std::chrono::steady_clock::now();
    const vision::ModelLocalization tracked = vision::localize_mesh(*mesh, depth, prior, true);
    const double tracked_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
    figures.tracking.add(tracked.found(), tracked.status, tracked.pose_world_object, truth, symmetries, tracked_ms);
  }
  std::printf("| part | method | found | wrong | position p50 / p95 | rotation p50 / p95 | time p50 / p99 | refused |\n");
  std::printf("|---|---|---|---|---|---|---|---|\n");
  figures.markers.print(name, "markers (full frame)");
  figures.prior.print(name, "model, prior 2 cm / 4 deg");
  figures.tracking.print(name, "model tracking, prior 2 cm / 4 deg");
  figures.global.print(name, "model, no prior");
  return figures;
}

int run() {
  performance::Report report("bench_markerless_localize",
                             "Markerless localization per frame (one core) next to the marker tracker, same frames");
  const std::map<std::string, PartFigures> parts = [] {
    std::map<std::string, PartFigures> out;
    const char* only = std::getenv("RIGGER_BENCH_PART");
    auto wanted = [&](const std::string& part) { return only == nullptr || part == only; };
    if (wanted("load"))
      out["load"] = run_part("load", std::string(RIGGER_SOURCE_DIR) + "/deploy/cell/simulated_cell.json", "load");
    sim::GeneratedCell generated;
    if (wanted("bracket")) out["bracket"] = run_part("bracket", generated.write(), "bracket");
    return out;
  }();
  for (const auto& [name, f] : parts) {
    const double marker_p50 = percentile(f.markers.time_ms, 0.5);
    report.add({name + ": model from a prior, p50", percentile(f.prior.time_ms, 0.5), "ms", "markers p50", marker_p50});
    report.add({name + ": model from a prior, p99", percentile(f.prior.time_ms, 0.99), "ms", "markers p99",
                percentile(f.markers.time_ms, 0.99)});
    report.add({name + ": model, no prior, p50", percentile(f.global.time_ms, 0.5), "ms", "markers p50", marker_p50});
    for (const auto& [method, tally] : {std::pair{"model, no prior", &f.global}, {"model from a prior", &f.prior}}) {
      const std::string figure = name + ": " + method + ", ";
      report.add({figure + "found", static_cast<double>(tally->found), "of " + std::to_string(kPoses), "markers found",
                  static_cast<double>(f.markers.found)});
      report.add({figure + "wrong", static_cast<double>(tally->wrong), "", "markers wrong",
                  static_cast<double>(f.markers.wrong)});
      report.add({figure + "position p95", percentile(tally->position_mm, 0.95), "mm", "markers position p95",
                  percentile(f.markers.position_mm, 0.95)});
    }
    report.add({name + ": model from a prior, rotation p95", percentile(f.prior.rotation_deg, 0.95), "deg",
                "markers rotation p95", percentile(f.markers.rotation_deg, 0.95)});
  }
  return performance::save_for_main(report);
}

}  // namespace

int main() {
  try {
    return run();
  } catch (const std::exception& e) {
    std::fprintf(stderr, "bench_markerless_localize: %s\n", e.what());
    return 2;
  }
}
