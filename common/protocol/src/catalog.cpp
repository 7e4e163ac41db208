#include "rigger/protocol/catalog.hpp"

#include <algorithm>
#include <sstream>

#include "rigger/protocol/admittance.hpp"
#include "rigger/protocol/cad.hpp"
#include "rigger/protocol/crane.hpp"
#include "rigger/protocol/operator.hpp"
#include "rigger/protocol/robot.hpp"
#include "rigger/protocol/safety.hpp"
#include "rigger/protocol/sim.hpp"
#include "rigger/protocol/skill.hpp"
#include "rigger/protocol/system.hpp"
#include "rigger/protocol/task.hpp"
#include "rigger/protocol/vision.hpp"
#include "rigger/protocol/world.hpp"

namespace rigger::protocol {
namespace {

// "rigger_operator_ui_OperatorPrompt" -> "rigger::operator_ui::OperatorPrompt": the type's name starts
// at the last '_' followed by an upper-case letter (IDL module names are lower case).
std::string idl_name(const std::string& c_name) {
  std::size_t split = std::string::npos;
  for (std::size_t i = 0; i + 1 < c_name.size(); ++i)
    if (c_name[i] == '_' && c_name[i + 1] >= 'A' && c_name[i + 1] <= 'Z') split = i;
  if (split == std::string::npos) return c_name;
  std::string modules = c_name.substr(0, split);
  const auto first = modules.find('_');
  if (first != std::string::npos) modules.replace(first, 1, "::");
  return modules + "::" + c_name.substr(split + 1);
}

template <typename T>
TopicInfo info(const char* area, const Topic<T>& t) {
  return {area,
          t.name,
          idl_name(idl::TypeSupport<T>::name()),
          idl::TypeSupport<T>::descriptor(),
          t.qos,
          t.key,
          t.writers,
          t.readers,
          t.summary,
          t.qos_note};
}

struct Area {
  const char* id;
  const char* title;
  const char* idl;
  const char* after_title;
  const char* notes;
};

const Area kAreas[] = {
    {"system", "System", "`idl/system.idl`", "", ""},
    {"task", "Task", "`idl/task.idl`", "", ""},
    {"skill", "Skill executors", "`idl/skill.idl`", "", ""},
    {"world", "World model", "`idl/world.idl`", "", ""},
    {"robot", "Robot and gripper", "`idl/robot.idl`, `idl/sensing.idl`", "", ""},
    {"crane", "Crane", "`idl/crane.idl`", "", ""},
    {"vision", "Camera and tracker", "`idl/vision.idl`", "", ""},
    {"sim", "Simulator", "`idl/sim.idl`", " — the simulated cell only ([cell-sim.md](cell-sim.md))", ""},
    {"admittance", "Admittance", "`idl/admittance.idl`", "",
     "admittance_control also reads `rigger/robot/wrench`, `rigger/robot/state`, `rigger/operator/joystick`,\n"
     "`rigger/tracker/pose` (the servo's object and target), `rigger/crane/state` (crane faults in\n"
     "ROBOT_AND_CRANE) and `rigger/system/service_state` (the commander's liveliness); it writes\n"
     "`rigger/robot/cmd_twist` (frame id = the robot's base frame, `robot` in the cell file) and\n"
     "`rigger/crane/cmd_velocity`. docs/control.md §7 has the details.\n"},
    {"operator", "Operator", "`idl/operator.idl`", "", ""},
    {"cad", "CAD", "`idl/cad.idl`", "", ""},
    {"safety", "Safety", "`idl/safety.idl`", " — the software safe stop ([safety.md](safety.md))", ""},
};

// The type as the reader of docs/topics.md knows it: "Recipe" in its own area, "sensing::WrenchStamped"
// from another module.
std::string short_type(const TopicInfo& t) {
  const std::string prefix = "rigger::";
  std::string name = t.idl_type.compare(0, prefix.size(), prefix) == 0 ? t.idl_type.substr(prefix.size()) : t.idl_type;
  const auto sep = name.rfind("::");
  if (sep == std::string::npos) return name;
  const std::string module = name.substr(0, sep);
  const bool own = module == t.area || (t.area == "operator" && module == "operator_ui");
  return own ? name.substr(sep + 2) : name;
}

std::size_t edit_distance(const std::string& a, const std::string& b) {
  std::vector<std::size_t> row(b.size() + 1);
  for (std::size_t j = 0; j <= b.size(); ++j) row[j] = j;
  for (std::size_t i = 1; i <= a.size(); ++i) {
    std::size_t diag = row[0];
    row[0] = i;
    for (std::size_t j = 1; j <= b.size(); ++j) {
      const std::size_t up = row[j];
      row[j] = std::min({row[j] + 1, row[j - 1] + 1, diag + (a[i - 1] == b[j - 1] ? 0 : 1)});
      diag = up;
    }
  }
  return row[b.size()];
}

}  // namespace

const std::vector<TopicInfo>& catalog() {
  static const std::vector<TopicInfo> all{
      info("system", system::kServiceState),
      info("system", system::kPeerView),
      info("system", system::kEchoRequest),
      info("system", system::kEchoReply),
      info("task", task::kRecipe),
      info("task", task::kCommand),
      info("task", task::kStatus),
      info("task", task::kNodeStatus),
      info("task", task::kJournalQuery),
      info("task", task::kJournalReply),
      info("skill", skill::kCommand),
      info("skill", skill::kEvent),
      info("skill", skill::kExecutors),
      info("world", world::kEntity),
      info("world", world::kUpdate),
      info("world", world::kUpdateResult),
      info("world", world::kChange),
      info("world", world::kQuery),
      info("world", world::kReply),
      info("world", world::kCell),
      info("world", world::kCellModel),
      info("world", world::kCellRequest),
      info("world", world::kCellReply),
      info("robot", robot::kWrench),
      info("robot", robot::kState),
      info("robot", robot::kCmdTwist),
      info("robot", robot::kCmdMotion),
      info("robot", robot::kMotionStatus),
      info("robot", robot::kGripperCmd),
      info("robot", robot::kGripperState),
      info("crane", crane::kState),
      info("crane", crane::kCmdVelocity),
      info("crane", crane::kControl),
      info("vision", vision::kCameraImage),
      info("vision", vision::kCameraDepth),
      info("vision", vision::kCameraInfo),
      info("vision", vision::kTrackerPose),
      info("vision", vision::kTrackerCommand),
      info("sim", sim::kGroundTruth),
      info("sim", sim::kControl),
      info("sim", sim::kEvent),
      info("sim", sim::kStatus),
      info("admittance", admittance::kCommand),
      info("admittance", admittance::kState),
      info("operator", operator_ui::kPrompt),
      info("operator", operator_ui::kResponse),
      info("operator", operator_ui::kJoystick),
      info("cad", cad::kRequest),
      info("cad", cad::kReply),
      info("safety", safety::kStop),
  };
  return all;
}

const TopicInfo* find_topic(const std::string& name) {
  for (const auto& t : catalog())
    if (t.name == name) return &t;
  return nullptr;
}

std::vector<std::string> close_topic_names(const std::string& name, std::size_t max) {
  const auto last = [](const std::string& s) { return s.substr(s.rfind('/') + 1); };
  std::vector<std::pair<std::size_t, std::string>> scored;
  for (const auto& t : catalog()) {
    std::size_t d = edit_distance(name, t.name);
    if (last(name) == last(t.name) || t.name.find(name) != std::string::npos) d = std::min<std::size_t>(d, 1);
    if (d <= std::max<std::size_t>(3, name.size() / 3)) scored.emplace_back(d, t.name);
  }
  std::stable_sort(scored.begin(), scored.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
  std::vector<std::string> out;
  for (const auto& [d, n] : scored) {
    if (out.size() == max) break;
    out.push_back(n);
  }
  return out;
}

std::string catalog_markdown() {
  std::ostringstream md;
  md << "# Topic catalog\n\n"
        "<!-- Generated from common/protocol (the topic descriptors) by tools/update-topic-reference; do not "
        "edit. -->\n\n"
        "Every topic rigger uses, with its type (in `idl/`), key, QoS profile "
        "(`common/dds/include/rigger/dds/qos.hpp`),\n"
        "writers and readers. Each is declared once, as a typed descriptor in "
        "`common/protocol/include/rigger/protocol/<area>.hpp`,\n"
        "which every service, riggerctl, test and benchmark opens it through. Types live in one IDL module per "
        "area and are all `@final`; SI units throughout;\n"
        "stamps are wall-clock time since the Unix epoch (`rigger::geometry::Time`, as ROS 2's "
        "`builtin_interfaces/Time`).\n"
        "Sensor, pose, twist and image types keep the field layout of ROS 2's `geometry_msgs` / `sensor_msgs`,\n"
        "so that a bridge is a renaming, not a conversion.\n\n"
        "QoS profiles:\n\n"
        "| profile | reliability | history | durability | extra | for |\n"
        "|---|---|---|---|---|---|\n"
        "| `commands()` | reliable | keep-all | volatile | | every command must arrive, in order |\n"
        "| `events()` | reliable | keep-all | volatile | | every event must arrive, in order |\n"
        "| `state()` | reliable | keep-last 1 per instance | transient-local | | latest state, late joiners see it "
        "at once |\n"
        "| `announcements(lease)` | reliable | keep-last 1 | transient-local | MANUAL_BY_PARTICIPANT liveliness, "
        "lease 150 ms (`dds::liveliness_lease()`) | who is alive; loss seen within the lease |\n"
        "| `sensor_stream()` | best effort | keep-last 1 | volatile | | high-rate data where only the newest "
        "matters |\n"
        "| `setpoints()` | reliable | keep-last 1 | volatile | | velocity setpoints: newest wins, age checked on "
        "receipt |\n";
  for (const auto& area : kAreas) {
    md << "\n## " << area.title << " (" << area.idl << ")" << area.after_title << "\n\n"
       << "| topic | type | key | QoS | writers → readers |\n"
       << "|---|---|---|---|---|\n";
    for (const auto& t : catalog()) {
      if (t.area != area.id) continue;
      md << "| `" << t.name << "` | `" << short_type(t) << "`" << (t.summary.empty() ? "" : " ") << t.summary << " | "
         << (t.key.empty() ? std::string("—") : "`" + t.key + "`") << " | " << to_string(t.qos)
         << (t.qos_note.empty() ? "" : " (" + t.qos_note + ")") << " | " << t.writers << " → " << t.readers << " |\n";
    }
    if (*area.notes) md << "\n" << area.notes;
  }
  return md.str();
}

}  // namespace rigger::protocol
