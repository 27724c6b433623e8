#pragma once
// A similarity transform x -> s R x + t: what relates two monocular maps (or a drifted map to
// itself), since monocular SLAM fixes position and rotation only up to a global scale.
#include <Eigen/Geometry>

namespace hiveslam::core {

struct Sim3 {
  Eigen::Quaterniond q = Eigen::Quaterniond::Identity();
  Eigen::Vector3d t = Eigen::Vector3d::Zero();
  double s = 1.0;

  Sim3() = default;
  Sim3(const Eigen::Quaterniond& q, const Eigen::Vector3d& t, double s) : q(q.normalized()), t(t), s(s) {}
  explicit Sim3(const Eigen::Isometry3d& T) : q(Eigen::Quaterniond(T.linear()).normalized()), t(T.translation()) {}

  Eigen::Vector3d operator*(const Eigen::Vector3d& x) const { return s * (q * x) + t; }
  Sim3 operator*(const Sim3& o) const { return {q * o.q, s * (q * o.t) + t, s * o.s}; }
  Sim3 inverse() const {
    const Eigen::Quaterniond qi = q.conjugate();
    return {qi, -(qi * t) / s, 1.0 / s};
  }
  // The rigid pose with the same rotation and a translation expressed at unit scale: a
  // keyframe's corrected T_cw from its corrected Sim3 S_cw = [sR | t].
  Eigen::Isometry3d toPose() const {
    Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
    T.linear() = q.toRotationMatrix();
    T.translation() = t / s;
    return T;
  }
};

}  // namespace hiveslam::core
