#include "relocalization.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <ctime>

namespace rigger::task_controller {
namespace {

using bt::NodeIndex;
using bt::NodeKind;
using nlohmann::json;

/// The predicate's arguments with "$param" replaced by the string value of the parameter ("" when it
/// is missing or not a string).
std::vector<std::string> ground_args(const skill::Predicate& p, const json& params) {
  std::vector<std::string> out;
  for (const auto& a : p.args) {
    if (a.empty() || a[0] != '$') {
      out.push_back(a);
      continue;
    }
    const auto it = params.find(a.substr(1));
    out.push_back(it != params.end() && it->is_string() ? it->get<std::string>() : std::string());
  }
  return out;
}

const skill::SkillDescription* description_of(const bt::NodeSpec& node, const skill::SkillLibrary& library) {
  if (node.kind != NodeKind::kSkill && node.kind != NodeKind::kCondition) return nullptr;
  return library.find(node.leaf);
}

/// Does `node` (a leaf still to run) use `object`: a precondition names it, or a string parameter is it
/// or one of its features ("load/grasp_side")?
bool uses(const bt::NodeSpec& node, const skill::SkillLibrary& library, const std::string& object) {
  if (const auto* d = description_of(node, library))
    for (const auto& p : d->preconditions)
      for (const auto& a : ground_args(p, node.params))
        if (a == object) return true;
  for (auto it = node.params.begin(); it != node.params.end(); ++it) {
    if (!it->is_string()) continue;
    const std::string v = it->get<std::string>();
    if (v == object || v.rfind(object + "/", 0) == 0) return true;
  }
  return false;
}

std::string utc_clock(double stamp_s) {
  const std::time_t t = static_cast<std::time_t>(std::floor(stamp_s));
  std::tm tm{};
  gmtime_r(&t, &tm);
  char buffer[32];
  std::strftime(buffer, sizeof buffer, "%H:%M:%S UTC", &tm);
  return buffer;
}

/// utc_clock with milliseconds ("12:01:03.250 UTC"): two moments within a second told apart.
std::string utc_clock_ms(double stamp_s) {
  const double whole = std::floor(stamp_s);
  const std::string hms = utc_clock(whole);
  char ms[8];
  std::snprintf(ms, sizeof ms, ".%03d", static_cast<int>(std::min(999.0, (stamp_s - whole) * 1000.0)));
  return hms.substr(0, 8) + ms + hms.substr(8);
}

std::string fixed(double v, int digits) {
  char buffer[64];
  std::snprintf(buffer, sizeof buffer, "%.*f", digits, v);
  return buffer;
}

/// "Localize(load) (root/1/0/0)" for each leaf, joined.
std::string leaves_text(const std::vector<std::string>& ids, const bt::TreeSpec& spec, const std::string& object) {
  std::string out;
  for (const auto& id : ids) {
    std::string what = id;
    for (const auto& n : spec.nodes)
      if (n.id == id) what = n.leaf + "(" + object + ") (" + id + (n.name.empty() ? "" : ", " + n.name) + ")";
    out += (out.empty() ? "" : " and ") + what;
  }
  return out;
}

}  // namespace

std::string localized_pose_row(const LocalizedPose& pose) {
  const Eigen::Vector3d t = pose.pose_world_object.translation();
  const Eigen::Quaterniond q(pose.pose_world_object.rotation());
  return json{{"object", pose.object},
              {"frame", kRecheckFrame},
              {"position_m", {t.x(), t.y(), t.z()}},
              {"quaternion_xyzw", {q.x(), q.y(), q.z(), q.w()}},
              {"stamp_s", pose.stamp_s}}
      .dump();
}

std::optional<LocalizedPose> localized_pose_from_row(const JournalRecord& row) {
  if (row.kind != kWorldRow || row.code != kLocalizedCode) return std::nullopt;
  const json j = json::parse(row.message, nullptr, false);
  if (!j.is_object()) return std::nullopt;
  try {
    LocalizedPose p;
    p.object = j.at("object").get<std::string>();
    if (j.at("frame").get<std::string>() != kRecheckFrame) return std::nullopt;
    const auto t = j.at("position_m").get<std::vector<double>>();
    const auto q = j.at("quaternion_xyzw").get<std::vector<double>>();
    if (t.size() != 3 || q.size() != 4) return std::nullopt;
    const Eigen::Quaterniond rotation(q[3], q[0], q[1], q[2]);
    if (std::abs(rotation.norm() - 1.0) > 1e-6) return std::nullopt;
    p.pose_world_object = Eigen::Isometry3d::Identity();
    p.pose_world_object.linear() = rotation.toRotationMatrix();
    p.pose_world_object.translation() = Eigen::Vector3d(t[0], t[1], t[2]);
    p.stamp_s = j.at("stamp_s").get<double>();
    if (!p.pose_world_object.matrix().allFinite() || !std::isfinite(p.stamp_s)) return std::nullopt;
    return p;
  } catch (const json::exception&) {
    return std::nullopt;
  }
}

std::map<std::string, std::string> localizing_leaves(const bt::TreeSpec& spec, const skill::SkillLibrary& library) {
  std::map<std::string, std::string> out;
  for (const auto& node : spec.nodes) {
    const auto* d = description_of(node, library);
    if (d == nullptr) continue;
    for (const auto& p : d->postconditions) {
      if (p.negated || p.name != "localized" || p.args.size() != 1) continue;
      const auto args = ground_args(p, node.params);
      if (!args[0].empty()) out[node.id] = args[0];
    }
  }
  return out;
}

std::vector<ObjectRecheck> objects_to_recheck(const bt::TreeSpec& spec, const ResumePlan& plan,
                                              const std::vector<JournalRecord>& timeline,
                                              const skill::SkillLibrary& library, const RecheckSettings& settings) {
  std::map<std::string, NodeIndex> index;
  std::map<NodeIndex, NodeIndex> parent;
  for (NodeIndex i = 0; i < spec.nodes.size(); ++i) {
    index[spec.nodes[i].id] = i;
    for (const NodeIndex c : spec.nodes[i].children) parent[c] = i;
  }
  // Each node's last state and the row of its last SUCCESS (journal order), each localization's pose.
  std::map<std::string, std::string> state;
  std::map<std::string, std::size_t> succeeded_at;
  std::map<std::string, std::pair<std::size_t, LocalizedPose>> pose_of;  // by node id: row, pose
  for (std::size_t k = 0; k < timeline.size(); ++k) {
    const auto& r = timeline[k];
    if (r.kind == "NODE") {
      state[r.node_id] = r.code;
      if (r.code == bt::to_string(bt::NodeState::kSuccess)) succeeded_at[r.node_id] = k;
    } else if (auto p = localized_pose_from_row(r)) {
      pose_of[r.node_id] = {k, *p};
    } else if (r.kind == kWorldRow) {
      pose_of.erase(r.node_id);  // POSE_UNKNOWN after an earlier run's pose: that pose is not this run's
    }
  }
  const auto success = std::string(bt::to_string(bt::NodeState::kSuccess));
  // Done: the leaf succeeded, and it or an ancestor on a path of successes is restored as done.
  const auto done = [&](NodeIndex leaf) {
    for (NodeIndex at = leaf;;) {
      if (state[spec.nodes[at].id] != success) return false;
      if (plan.restoration.nodes.size() == spec.nodes.size() &&
          plan.restoration.nodes[at].how == bt::Restored::kSucceeded)
        return true;
      const auto p = parent.find(at);
      if (p == parent.end()) return false;
      at = p->second;
    }
  };
  // The crashed controller's last row: the one before the latest TASK INTERRUPTED (its successor's).
  double interrupted_at_s = 0;
  for (std::size_t k = 0; k < timeline.size(); ++k)
    if (timeline[k].kind == "TASK" && timeline[k].code == "INTERRUPTED" && k > 0)
      interrupted_at_s = timeline[k - 1].stamp_s;
  std::vector<std::string> remaining = plan.rerun;
  remaining.insert(remaining.end(), plan.ask.begin(), plan.ask.end());
  remaining.insert(remaining.end(), plan.pending.begin(), plan.pending.end());

  std::vector<ObjectRecheck> out;
  std::map<std::string, std::size_t> slot;           // object → its entry in out
  std::map<std::string, std::size_t> localized_row;  // object → row of its latest done localization
  for (const auto& [node_id, object] : localizing_leaves(spec, library)) {
    if (!done(index.at(node_id))) continue;
    std::vector<std::string> users;
    for (const auto& id : remaining)
      if (id != node_id && uses(spec.nodes[index.at(id)], library, object)) users.push_back(id);
    if (users.empty()) continue;
    auto [it, added] = slot.emplace(object, out.size());
    if (added) {
      ObjectRecheck c;
      c.object = object;
      c.used_by = users;
      c.max_age_s = settings.max_age_s;
      c.interrupted_at_s = interrupted_at_s;
      out.push_back(c);
    }
    ObjectRecheck& c = out[it->second];
    c.localized_by.push_back(node_id);
    const std::size_t row = succeeded_at[node_id];
    if (!localized_row.count(object) || row > localized_row[object]) {
      localized_row[object] = row;
      const auto p = pose_of.find(node_id);
      // Only a pose journaled after this success belongs to it (an earlier run's is not this one's).
      c.recorded =
          p != pose_of.end() && p->second.first > row ? std::optional<LocalizedPose>(p->second.second) : std::nullopt;
    }
  }
  for (auto& c : out) {
    // The recipe's freshness demand on the object, if any.
    for (const auto& node : spec.nodes) {
      if (node.kind != NodeKind::kCondition || node.leaf != "ObjectLocalized") continue;
      const auto o = node.params.find("object");
      const auto a = node.params.find("max_age_s");
      if (o == node.params.end() || !o->is_string() || o->get<std::string>() != c.object) continue;
      if (a != node.params.end() && a->is_number() && a->get<double>() > 0)
        c.max_age_s = std::min(c.max_age_s, a->get<double>());
    }
    // Carried: a done skill after the localization attached it, and no done skill after that let go.
    std::size_t attached_row = 0;
    for (const auto& node : spec.nodes) {
      const auto* d = description_of(node, library);
      const auto at = succeeded_at.find(node.id);
      if (d == nullptr || at == succeeded_at.end() || at->second < localized_row[c.object]) continue;
      if (!done(index.at(node.id))) continue;
      for (const auto& p : d->postconditions) {
        if (p.name != "attached") continue;
        const auto args = ground_args(p, node.params);
        if (std::find(args.begin(), args.end(), c.object) == args.end()) continue;
        if (!p.negated && at->second >= attached_row) {
          attached_row = at->second;
          c.carried_by = node.id;
        } else if (p.negated && at->second >= attached_row) {
          attached_row = at->second;
          c.carried_by.clear();
        }
      }
    }
  }
  return out;
}

void judge(ObjectRecheck& c, const world_client::Reply& now, const RecheckSettings& settings,
           const bt::TreeSpec& spec) {
  c.now = now;
  const std::string again = leaves_text(c.localized_by, spec, c.object);
  const std::string when = c.recorded ? " since it was localized at " + utc_clock(c.recorded->stamp_s)
                                      : std::string(" since its localization");
  c.relocalize = true;
  c.preconditions_hold = false;
  if (!now.ok) {
    const bool unreachable = now.code == "WORLD_UNREACHABLE";
    c.verdict = unreachable ? "unknown" : "not_localized";
    c.reason = (unreachable ? "the world model did not answer about " + c.object
                            : "the world model has no pose of " + c.object) +
               " (" + now.code + (now.message.empty() ? "" : ": " + now.message) + "); " + again +
               " will run again to be safe";
    return;
  }
  if (c.recorded) {
    const Eigen::Isometry3d delta = c.recorded->pose_world_object.inverse() * now.pose;
    c.displacement_m = (now.pose.translation() - c.recorded->pose_world_object.translation()).norm();
    c.rotation_deg = Eigen::AngleAxisd(delta.rotation()).angle() * 180.0 / M_PI;
  }
  const std::string age = "pose " + fixed(now.age_s, 1) + " s old";
  if (!now.localized) {
    c.verdict = "not_localized";
    c.reason = "the world model marks " + c.object + " as not localized; " + again + " will run again";
    return;
  }
  if (now.age_s > c.max_age_s) {
    c.verdict = "stale";
    c.reason = c.object + "'s pose is " + fixed(now.age_s, 1) + " s old, older than its max age " +
               fixed(c.max_age_s, 1) + " s; " + again + " will run again";
    return;
  }
  if (!c.carried_by.empty()) {
    c.verdict = "carried";
    c.relocalize = false;
    c.preconditions_hold = true;
    std::string by = c.carried_by;
    for (const auto& n : spec.nodes)
      if (n.id == c.carried_by) by = describe_node(spec, n.id);
    c.reason = c.object + " has been attached by " + by + when + " and moves with the robot (" +
               fixed(c.displacement_m * 1000.0, 0) + " mm from that pose, " + age + "): its localization stays done";
    return;
  }
  if (!c.recorded) {
    c.verdict = "unrecorded";
    c.reason = "no pose of " + c.object +
               " was journaled when it was localized (the controller stopped before the world model answered); " +
               again + " will run again to be safe";
    return;
  }
  const double observed_at_s = c.checked_at_s - now.age_s;
  if (c.interrupted_at_s > 0 && c.checked_at_s > 0 && observed_at_s <= c.interrupted_at_s) {
    c.verdict = "unconfirmed";
    c.reason = "nothing has seen " + c.object + " since the controller stopped (the world model's pose of it was observed at " +
               utc_clock_ms(observed_at_s) + ", the controller's last journal row is of " + utc_clock_ms(c.interrupted_at_s) +
               "): it may have been moved; " + again + " will run again";
    return;
  }
  const std::string moved = fixed(c.displacement_m * 1000.0, 0) + " mm and " + fixed(c.rotation_deg, 1) + " deg";
  if (c.displacement_m > settings.tolerance_m || c.rotation_deg > settings.tolerance_deg) {
    c.verdict = "moved";
    c.reason = c.object + " moved " + moved + when + " (" + age + "); " + again + " will run again";
    return;
  }
  c.verdict = "unchanged";
  c.relocalize = false;
  c.preconditions_hold = true;
  c.reason =
      c.object + " is where it was localized (" + moved + " off" + when + ", " + age + "): its localization stays done";
}

std::set<std::string> leaves_to_relocalize(const std::vector<ObjectRecheck>& checks) {
  std::set<std::string> out;
  for (const auto& c : checks)
    if (c.relocalize) out.insert(c.localized_by.begin(), c.localized_by.end());
  return out;
}

json to_json(const std::vector<ObjectRecheck>& checks) {
  json out = json::array();
  for (const auto& c : checks) {
    json j = {{"object", c.object},         {"verdict", c.verdict},
              {"relocalize", c.relocalize}, {"preconditions_hold", c.preconditions_hold},
              {"max_age_s", c.max_age_s},   {"localized_by", c.localized_by},
              {"used_by", c.used_by},       {"carried_by", c.carried_by},
              {"reason", c.reason}};
    if (c.now && c.now->ok) {
      j["world_model"] = "answered";
      j["localized"] = c.now->localized;
      j["pose_age_s"] = c.now->age_s;
    } else {
      j["world_model"] = c.now ? c.now->code + (c.now->message.empty() ? "" : ": " + c.now->message) : "not asked";
      j["localized"] = nullptr;
      j["pose_age_s"] = nullptr;
    }
    if (c.recorded) {
      j["localized_at_s"] = c.recorded->stamp_s;
      j["localized_at"] = utc_clock(c.recorded->stamp_s);
    }
    if (c.recorded && c.now && c.now->ok) {
      j["displacement_mm"] = c.displacement_m * 1000.0;
      j["rotation_deg"] = c.rotation_deg;
    } else {
      j["displacement_mm"] = nullptr;
      j["rotation_deg"] = nullptr;
    }
    out.push_back(j);
  }
  return out;
}

std::string describe_checks(const std::vector<ObjectRecheck>& checks) {
  std::string out;
  for (const auto& c : checks)
    out += (out.empty() ? "" : "\n") + std::string("world: ") + c.reason + " (preconditions " +
           (c.preconditions_hold ? "hold" : "do not hold") + ")";
  return out;
}

}  // namespace rigger::task_controller
