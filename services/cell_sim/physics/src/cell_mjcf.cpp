// The cell's MuJoCo model: the device MJCF (models/cell.xml: crane, robot, gripper) with one body per
// object of the cell file generated into it, compiled from memory (a MuJoCo VFS).
#include "cell_mjcf.hpp"

#include <array>
#include <fstream>
#include <iomanip>
#include <memory>
#include <sstream>

namespace rigger::sim::detail {
namespace {

// Where the generated text goes in the device MJCF.
constexpr std::string_view kAssetMarker = "<!-- rigger:object assets -->";
constexpr std::string_view kHookMarker = "<!-- rigger:hooked object -->";
constexpr std::string_view kWorldMarker = "<!-- rigger:objects -->";
constexpr std::string_view kBoardMarker = "<!-- rigger:calibration board -->";

// Name under which the generated MJCF is compiled (MuJoCo's messages quote it).
constexpr const char* kVfsName = "rigger_cell.xml";

std::string escaped(const std::string& text) {
  std::string out;
  for (const char c : text) {
    switch (c) {
      case '&': out += "&amp;"; break;
      case '<': out += "&lt;"; break;
      case '>': out += "&gt;"; break;
      case '"': out += "&quot;"; break;
      default: out += c;
    }
  }
  return out;
}

// Doubles written so that MuJoCo parses back the same double (the model stays what the cell file says).
class Numbers {
 public:
  explicit Numbers(int digits = 17) { text_ << std::setprecision(digits); }
  Numbers& operator<<(double value) {
    if (!first_) text_ << ' ';
    text_ << value;
    first_ = false;
    return *this;
  }
  Numbers& operator<<(const Eigen::Vector3d& v) { return *this << v.x() << v.y() << v.z(); }
  Numbers& operator<<(const Eigen::Quaterniond& q) { return *this << q.w() << q.x() << q.y() << q.z(); }
  std::string str() const { return text_.str(); }

 private:
  std::ostringstream text_;
  bool first_ = true;
};

template <typename T>
std::string numbers(const T& value) {
  Numbers out;
  out << value;
  return out.str();
}

void write_geoms(const ObjectGeometry& object, std::ostream& bodies, std::ostream& assets) {
  const char* geom_class = object.is_static ? "static_env" : "free_object";
  const std::string id = escaped(object.id);
  // A static body's mass does nothing; a free body's is the object's, shared by the solids' volumes.
  const auto mass = [&](double fraction) {
    return object.is_static ? std::string() : " mass=\"" + numbers(fraction * object.mass_kg) + "\"";
  };
  if (object.box_size_m) {
    bodies << "      <geom name=\"" << id << "\" class=\"" << geom_class << "\" type=\"box\" pos=\""
           << numbers(object.box_centre_m) << "\" size=\"" << numbers(Eigen::Vector3d(0.5 * *object.box_size_m))
           << "\"" << mass(1.0) << "/>\n";
    return;
  }
  double volume = 0.0;
  for (const ObjectSolid& solid : object.solids) volume += solid.volume_m3;
  for (std::size_t k = 0; k < object.solids.size(); ++k) {
    const std::string name = id + "_solid" + std::to_string(k);
    Numbers vertices(9);
    for (const Eigen::Vector3d& vertex : object.solids[k].vertices_m) vertices << vertex;
    assets << "    <mesh name=\"" << name << "\" vertex=\"" << vertices.str() << "\"/>\n";
    bodies << "      <geom name=\"" << name << "\" class=\"" << geom_class << "\" type=\"mesh\" mesh=\"" << name
           << "\"" << mass(object.solids[k].volume_m3 / volume) << "/>\n";
  }
}

// The calibration board on the tool, in the gripper body (its frame the flange's; the tool frame is the
// magnet's face, flange_to_face_m along z): drawn, massless, colliding with nothing, so that the arm's
// dynamics and the wrist sensor are the same with it as without.
std::string board_geom(const CellGeometry& cell) {
  if (!cell.robot.calibration_board) return "";
  const cell::CalibrationBoard& board = *cell.robot.calibration_board;
  const Eigen::Isometry3d pose_gripper_board =
      Eigen::Translation3d(0.0, 0.0, cell.gripper.flange_to_face_m) * board.pose_tool_board;
  return "<geom name=\"calibration_board\" class=\"visual\" type=\"box\" pos=\"" +
         numbers(Eigen::Vector3d(pose_gripper_board.translation())) + "\" quat=\"" +
         numbers(Eigen::Quaterniond(pose_gripper_board.linear())) + "\" size=\"" +
         numbers(Eigen::Vector3d(0.5 * board.size_m)) + "\" rgba=\"0.92 0.92 0.92 1\"/>";
}

void replace_marker(std::string& xml, std::string_view marker, const std::string& text,
                    const std::filesystem::path& device_path) {
  const std::size_t at = xml.find(marker);
  if (at == std::string::npos) {
    throw PhysicsModelError(device_path.string() + ": the device model lacks the marker '" + std::string(marker) +
                            "' where the cell's objects go");
  }
  xml.replace(at, marker.size(), text);
}

struct VfsDeleter {
  void operator()(mjVFS* vfs) const noexcept {
    mj_deleteVFS(vfs);
    delete vfs;
  }
};

}  // namespace

std::string cell_mjcf(std::string device_xml, const CellGeometry& cell, const std::filesystem::path& device_path) {
  std::ostringstream assets;
  std::ostringstream hooked;
  std::ostringstream world;
  for (const ObjectGeometry& object : cell.objects) {
    const std::string id = escaped(object.id);
    std::ostringstream geoms;
    write_geoms(object, geoms, assets);
    if (object.id == cell.load.id) {
      // Hung from the hook by a ball joint at its rope attachment (a swivel hook with a short sling); the
      // body frame is the object's, the hook sits at the attachment point.
      const Eigen::Vector3d attachment = cell.load.pose_load_rope_attachment.translation();
      hooked << "<body name=\"" << id << "\" pos=\"" << numbers(Eigen::Vector3d(-attachment)) << "\">\n"
             << "      <joint name=\"" << id << "_swivel\" type=\"ball\" pos=\"" << numbers(attachment)
             << "\" damping=\"2.0\"/>\n"
             << geoms.str() << "      <site name=\"" << id << "_rope_attachment\" pos=\"" << numbers(attachment)
             << "\" size=\"0.01\"/>\n    </body>";
      continue;
    }
    const Eigen::Quaterniond rotation(object.pose_world_object.linear());
    world << "<body name=\"" << id << "\" pos=\"" << numbers(Eigen::Vector3d(object.pose_world_object.translation()))
          << "\" quat=\"" << numbers(rotation) << "\">\n";
    if (!object.is_static) world << "      <freejoint name=\"" << id << "_free\"/>\n";
    world << geoms.str() << "    </body>\n    ";
  }
  const std::string asset_text = assets.str();
  replace_marker(device_xml, kAssetMarker, asset_text.empty() ? "" : "<asset>\n" + asset_text + "  </asset>",
                 device_path);
  replace_marker(device_xml, kHookMarker, hooked.str(), device_path);
  replace_marker(device_xml, kWorldMarker, world.str(), device_path);
  replace_marker(device_xml, kBoardMarker, board_geom(cell), device_path);
  return device_xml;
}

ModelPtr load_cell_model(const std::filesystem::path& device_path, const CellGeometry& cell) {
  std::ifstream in(device_path, std::ios::binary);
  if (!in) throw PhysicsModelError(device_path.string() + ": cannot read the device model");
  std::ostringstream text;
  text << in.rdbuf();
  const std::string xml = cell_mjcf(text.str(), cell, device_path);

  // mjVFS holds its file table inline (megabytes): on the heap.
  const std::unique_ptr<mjVFS, VfsDeleter> vfs(new mjVFS);
  mj_defaultVFS(vfs.get());
  if (mj_makeEmptyFileVFS(vfs.get(), kVfsName, static_cast<int>(xml.size())) != 0) {
    throw PhysicsModelError("MuJoCo could not make room for the generated model");
  }
  const int file = mj_findFileVFS(vfs.get(), kVfsName);
  std::copy(xml.begin(), xml.end(), static_cast<char*>(vfs->filedata[file]));
  std::array<char, 1024> error{};
  ModelPtr model(mj_loadXML(kVfsName, vfs.get(), error.data(), static_cast<int>(error.size())));
  if (!model) {
    throw PhysicsModelError(device_path.string() + " with the objects of " + cell.source +
                            ": MuJoCo cannot load the model: " + error.data());
  }
  return model;
}

}  // namespace rigger::sim::detail
