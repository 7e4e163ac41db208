#include "face_directions.hpp"

#include <algorithm>
#include <cmath>

namespace rigger::perception::detail {

namespace {

constexpr double kConeCos = 0.985;     // 10 degrees
constexpr double kSetAsideCos = 0.94;  // 20 degrees
constexpr double kSameAngleRad = 10.0 * M_PI / 180.0;
constexpr double kPlaneGapM = 0.005;
constexpr std::size_t kPeakCandidates = 300;
constexpr std::size_t kPeakCounted = 1200;

// An orthonormal frame whose first axis is `a` and whose second lies in the plane of `a` and `b`.
Eigen::Matrix3d frame_of(const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  const Eigen::Vector3d z = a.cross(b).normalized();
  Eigen::Matrix3d frame;
  frame.col(0) = a;
  frame.col(1) = z.cross(a);
  frame.col(2) = z;
  return frame;
}

// The planes among offsets along a normal: runs without a gap over 5 mm, each holding a fifth of them
// (their median).
std::vector<double> planes(std::vector<double> offsets) {
  std::sort(offsets.begin(), offsets.end());
  std::vector<double> out;
  std::size_t begin = 0;
  for (std::size_t i = 1; i <= offsets.size(); ++i) {
    if (i == offsets.size() || offsets[i] - offsets[i - 1] > kPlaneGapM) {
      if (5 * (i - begin) >= offsets.size()) {
        out.push_back(offsets[(begin + i) / 2]);
      }
      begin = i;
    }
  }
  return out;
}

}  // namespace

std::vector<Eigen::Vector3d> positions_on_planes(const FaceMatch& match, const std::vector<FaceDirection>& image,
                                                 const std::vector<FaceDirection>& model,
                                                 const Eigen::Vector3d& start) {
  std::vector<Eigen::Vector3d> out;
  const FaceDirection& a = image[static_cast<std::size_t>(match.image_first)];
  const FaceDirection& m = model[static_cast<std::size_t>(match.model_first)];
  if (a.offsets_m.empty()) {
    return out;
  }
  const bool two = match.image_second >= 0;
  const FaceDirection* b = two ? &image[static_cast<std::size_t>(match.image_second)] : nullptr;
  const FaceDirection* n = two ? &model[static_cast<std::size_t>(match.model_second)] : nullptr;
  if (two && b->offsets_m.empty()) {
    return out;
  }
  Eigen::Matrix<double, 3, 2> normals;
  normals.col(0) = a.normal;
  normals.col(1) = two ? b->normal : Eigen::Vector3d::Zero();
  for (const double e : m.offsets_m) {
    for (std::size_t k = 0; k < (two ? n->offsets_m.size() : 1); ++k) {
      // The plane normal · (R y + t) = d: normal · t = d - e.
      Eigen::Vector2d wanted(a.offsets_m.front() - e, two ? b->offsets_m.front() - n->offsets_m[k] : 0.0);
      if (!two) {
        out.push_back(start + a.normal * (wanted.x() - a.normal.dot(start)));
        continue;
      }
      const Eigen::Matrix2d gram = normals.transpose() * normals;
      const Eigen::Vector2d residual = wanted - normals.transpose() * start;
      out.push_back(start + normals * gram.ldlt().solve(residual));
    }
  }
  return out;
}

std::vector<FaceDirection> face_directions(const std::vector<Eigen::Vector3d>& points_m,
                                           const std::vector<Eigen::Vector3d>& normals, double min_share,
                                           int max_directions) {
  std::vector<FaceDirection> out;
  if (normals.empty()) {
    return out;
  }
  std::vector<char> left(normals.size(), 1);
  const auto total = static_cast<double>(normals.size());
  // The peak is looked for among a few hundred of the normals, its neighbours counted among a thousand or so:
  // the cone is wide enough for either to hold a face's share.
  const std::size_t peak_stride = std::max<std::size_t>(1, normals.size() / kPeakCandidates);
  const std::size_t count_stride = std::max<std::size_t>(1, normals.size() / kPeakCounted);
  while (static_cast<int>(out.size()) < max_directions) {
    std::size_t peak = 0;
    int peak_count = -1;
    for (std::size_t i = 0; i < normals.size(); i += peak_stride) {
      if (!left[i]) {
        continue;
      }
      int count = 0;
      for (std::size_t j = 0; j < normals.size(); j += count_stride) {
        count += left[j] && normals[i].dot(normals[j]) > kConeCos ? 1 : 0;
      }
      if (count > peak_count) {
        peak_count = count;
        peak = i;
      }
    }
    if (peak_count < 0) {
      break;
    }
    int members = 0;
    for (std::size_t j = 0; j < normals.size(); ++j) {
      members += left[j] && normals[peak].dot(normals[j]) > kConeCos ? 1 : 0;
    }
    if (members < min_share * total) {
      break;
    }
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    for (std::size_t j = 0; j < normals.size(); ++j) {
      if (left[j] && normals[peak].dot(normals[j]) > kConeCos) {
        sum += normals[j];
      }
    }
    const Eigen::Vector3d mean = sum.normalized();
    std::vector<double> offsets;
    for (std::size_t j = 0; j < normals.size(); ++j) {
      if (left[j] && mean.dot(normals[j]) > kConeCos) {
        offsets.push_back(mean.dot(points_m[j]));
      }
      if (mean.dot(normals[j]) > kSetAsideCos) {
        left[j] = 0;
      }
    }
    out.push_back({mean, members / total, planes(offsets)});
  }
  return out;
}

std::vector<FaceMatch> orientations_from_faces(const std::vector<FaceDirection>& image,
                                               const std::vector<FaceDirection>& model, int turns) {
  std::vector<FaceMatch> out;
  for (std::size_t f = 0; f < image.size(); ++f) {
    for (std::size_t g = 0; g < image.size(); ++g) {
      if (f == g) {
        continue;
      }
      const Eigen::Vector3d& a = image[f].normal;
      const Eigen::Vector3d& b = image[g].normal;
      const double angle = std::acos(std::clamp(a.dot(b), -1.0, 1.0));
      const Eigen::Matrix3d image_frame = frame_of(a, b);
      for (std::size_t i = 0; i < model.size(); ++i) {
        for (std::size_t j = 0; j < model.size(); ++j) {
          const double model_angle = std::acos(std::clamp(model[i].normal.dot(model[j].normal), -1.0, 1.0));
          if (i != j && std::abs(model_angle - angle) <= kSameAngleRad) {
            out.push_back({image_frame * frame_of(model[i].normal, model[j].normal).transpose(), static_cast<int>(f),
                           static_cast<int>(i), static_cast<int>(g), static_cast<int>(j)});
          }
        }
      }
    }
  }
  if (out.empty() && !image.empty()) {
    const Eigen::Vector3d& a = image[0].normal;
    for (std::size_t i = 0; i < model.size(); ++i) {
      const Eigen::Matrix3d onto = Eigen::Quaterniond::FromTwoVectors(model[i].normal, a).toRotationMatrix();
      for (int t = 0; t < turns; ++t) {
        out.push_back({Eigen::AngleAxisd(2.0 * M_PI * t / turns, a) * onto, 0, static_cast<int>(i), -1, -1});
      }
    }
  }
  return out;
}

Eigen::Isometry3d placed(const SurfacePoints& points, const Eigen::Matrix3d& rotation,
                         const Eigen::Vector3d& centroid_camera_m) {
  const Eigen::Vector3d view = centroid_camera_m.normalized();
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  int facing = 0;
  for (std::size_t i = 0; i < points.points_m.size(); ++i) {
    if ((rotation * points.normals[i]).dot(view) < 0.0) {
      sum += rotation * points.points_m[i];
      ++facing;
    }
  }
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  pose.linear() = rotation;
  pose.translation() = centroid_camera_m - (facing > 0 ? Eigen::Vector3d(sum / facing) : Eigen::Vector3d::Zero());
  return pose;
}

std::vector<Eigen::Isometry3d> face_hypotheses(const DepthGrid& grid, const Surface& surface,
                                               const std::vector<FaceDirection>& model_faces,
                                               const SurfacePoints& points, double min_share, int image_faces,
                                               int turns) {
  std::vector<Eigen::Vector3d> positions;
  std::vector<Eigen::Vector3d> normals;
  const std::size_t every = std::max<std::size_t>(1, surface.cells.size() / 1500);
  for (std::size_t i = 0; i < surface.cells.size(); i += every) {
    positions.push_back(grid.point(surface.cells[i]));
    normals.push_back(grid.normal(surface.cells[i]));
  }
  const std::vector<FaceDirection> image = face_directions(positions, normals, min_share, image_faces);
  std::vector<Eigen::Isometry3d> out;
  for (const FaceMatch& match : orientations_from_faces(image, model_faces, turns)) {
    const Eigen::Isometry3d start = placed(points, match.rotation, surface.centroid_m);
    for (const Eigen::Vector3d& t : positions_on_planes(match, image, model_faces, start.translation())) {
      Eigen::Isometry3d pose = start;
      pose.translation() = t;
      out.push_back(pose);
    }
  }
  return out;
}

}  // namespace rigger::perception::detail
