#include "eval/similarity.hpp"

#include <Eigen/Dense>
#include <Eigen/Geometry>

namespace hiveslam::eval {

Eigen::Isometry3d Similarity::apply(const Eigen::Isometry3d& T_wc) const {
  Eigen::Isometry3d out = Eigen::Isometry3d::Identity();
  out.linear() = rotation * T_wc.linear();
  out.translation() = (*this) * T_wc.translation();
  return out;
}

Similarity umeyama(const Eigen::Matrix3Xd& from, const Eigen::Matrix3Xd& to, bool with_scale) {
  const Eigen::Matrix4d M = Eigen::umeyama(from, to, with_scale);
  Similarity s;
  s.scale = with_scale ? M.block<3, 1>(0, 0).norm() : 1.0;
  s.rotation = M.block<3, 3>(0, 0) / s.scale;
  s.translation = M.block<3, 1>(0, 3);
  return s;
}

}  // namespace hiveslam::eval
