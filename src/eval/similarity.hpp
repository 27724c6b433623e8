#pragma once
// A similarity transform x -> s R x + t and its least-squares estimate from point pairs
// (Umeyama 1991; Eigen's implementation, the same rules as evo's).
#include <Eigen/Geometry>

namespace hiveslam::eval {

struct Similarity {
  double scale = 1.0;
  Eigen::Matrix3d rotation = Eigen::Matrix3d::Identity();
  Eigen::Vector3d translation = Eigen::Vector3d::Zero();

  Eigen::Vector3d operator*(const Eigen::Vector3d& x) const {
    return scale * (rotation * x) + translation;
  }
  // Applies the transform to a camera pose: the position as a point, the orientation rotated.
  Eigen::Isometry3d apply(const Eigen::Isometry3d& T_wc) const;
};

// The transform that maps `from` (3xN) onto `to` (3xN) in the least-squares sense; with
// with_scale false the scale stays 1 (SE3). Needs N >= 3 non-collinear points.
Similarity umeyama(const Eigen::Matrix3Xd& from, const Eigen::Matrix3Xd& to, bool with_scale);

}  // namespace hiveslam::eval
