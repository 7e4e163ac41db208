#pragma once
// The physics' own positions, for comparing with what the console's Replay shows in its 3D cell: the
// load's true pose (rigger/sim/ground_truth) and the crane's true axis positions (rigger/sim/status:
// x bridge, y trolley, z hook height, in the crane frame), each with the simulator's wall-clock stamp.
#include <algorithm>
#include <cmath>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Core>
#include <nlohmann/json.hpp>

#include "rigger/dds/conversions.hpp"
#include "rigger/dds/pubsub.hpp"
#include "rigger/dds/qos.hpp"
#include "rigger/protocol/sim.hpp"
#include "rigger/testing/cell.hpp"

namespace rigger::testing::scenario {

class CellTrace {
 public:
  explicit CellTrace(Cell& cell)
      : truth_(cell.participant(), protocol::sim::kGroundTruth, deep(protocol::sim::kGroundTruth)),
        status_(cell.participant(), protocol::sim::kStatus, deep(protocol::sim::kStatus)) {
    cell.loop().on_data(truth_, [this] {
      truth_.take([this](const rigger_vision_TrackedPose& p, const dds_sample_info_t&) {
        if (dds::to_string(p.object_id) == "load")
          load_.emplace_back(stamp_s(p.header.stamp), dds::to_domain(p.pose.pose).translation());
      });
    });
    cell.loop().on_data(status_, [this] {
      status_.take([this](const rigger_sim_SimStatus& s, const dds_sample_info_t&) {
        hook_.emplace_back(stamp_s(s.header.stamp),
                           Eigen::Vector3d(s.crane_position_m[0], s.crane_position_m[1], s.crane_position_m[2]));
      });
    });
  }

  /// How far `page` (m) is from the nearest true load (or hook) position stamped in [t - window_s, t]:
  /// the page shows the latest value the console sent at or before t, sent at most 10 times a second.
  /// NaN when no sample is in the window.
  double load_error(const nlohmann::json& page, double t, double window_s) const {
    return error(load_, page, t, window_s);
  }
  double hook_error(const nlohmann::json& page, double t, double window_s) const {
    return error(hook_, page, t, window_s);
  }
  std::size_t samples() const { return load_.size() + hook_.size(); }

 private:
  using Samples = std::vector<std::pair<double, Eigen::Vector3d>>;
  template <typename T>
  static dds::Qos deep(const protocol::Topic<T>& topic) {
    dds::Qos q = dds::qos::of(topic.qos);
    q.keep_last(1024);
    return q;
  }
  static double stamp_s(const rigger_geometry_Time& t) { return t.sec + 1e-9 * t.nanosec; }
  static double error(const Samples& samples, const nlohmann::json& page, double t, double window_s) {
    if (!page.is_array() || page.size() != 3) return std::nan("");
    const Eigen::Vector3d p(page[0].get<double>(), page[1].get<double>(), page[2].get<double>());
    double best = std::nan("");
    for (const auto& [stamp, truth] : samples) {
      if (stamp < t - window_s || stamp > t) continue;
      const double d = (truth - p).norm();
      if (std::isnan(best) || d < best) best = d;
    }
    return best;
  }

  dds::Reader<rigger_vision_TrackedPose> truth_;
  dds::Reader<rigger_sim_SimStatus> status_;
  Samples load_, hook_;
};

}  // namespace rigger::testing::scenario
