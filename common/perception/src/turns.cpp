#include "turns.hpp"

#include <cmath>

namespace rigger::perception::detail {

std::vector<Eigen::Matrix3d> orientation_samples(int directions, int turns) {
  std::vector<Eigen::Matrix3d> out;
  out.reserve(static_cast<std::size_t>(directions) * static_cast<std::size_t>(turns));
  const double golden = M_PI * (3.0 - std::sqrt(5.0));
  for (int i = 0; i < directions; ++i) {
    const double z = 1.0 - (i + 0.5) * 2.0 / directions;
    const double r = std::sqrt(1.0 - z * z);
    const Eigen::Vector3d direction(r * std::cos(golden * i), r * std::sin(golden * i), z);
    const Eigen::Matrix3d align =
        Eigen::Quaterniond::FromTwoVectors(Eigen::Vector3d::UnitZ(), direction).toRotationMatrix();
    for (int t = 0; t < turns; ++t) {
      out.push_back(align * Eigen::AngleAxisd(2.0 * M_PI * t / turns, Eigen::Vector3d::UnitZ()).toRotationMatrix());
    }
  }
  return out;
}

std::vector<Turn> turns_onto_itself(const SurfacePoints& points,
                                    const std::function<double(const Eigen::Vector3d&)>& distance,
                                    const Eigen::Vector3d& centre_m, double tolerance_m) {
  const std::vector<Turn> candidates = {
      {{}, Eigen::AngleAxisd(M_PI, Eigen::Vector3d::UnitX()).toRotationMatrix(), "2-fold about x"},
      {{}, Eigen::AngleAxisd(M_PI, Eigen::Vector3d::UnitY()).toRotationMatrix(), "2-fold about y"},
      {{}, Eigen::AngleAxisd(M_PI, Eigen::Vector3d::UnitZ()).toRotationMatrix(), "2-fold about z"},
      {{}, Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitZ()).toRotationMatrix(), "4-fold about z"}};
  std::vector<Turn> out;
  for (Turn turn : candidates) {
    // About the centroid: the symmetry maps the part onto itself where it stands.
    turn.about_centre = Eigen::Translation3d(centre_m) * Eigen::Isometry3d(turn.rotation) * Eigen::Translation3d(-centre_m);
    int off = 0;
    int checked = 0;
    bool maps = true;
    for (std::size_t i = 0; i < points.points_m.size() && maps; i += 3) {
      const double d = distance(turn.about_centre * points.points_m[i]);
      ++checked;
      off += d >= tolerance_m ? 1 : 0;
      maps = d < 3.0 * tolerance_m;
    }
    if (maps && off <= checked / 100) {
      out.push_back(turn);
    }
  }
  return out;
}

}  // namespace rigger::perception::detail
