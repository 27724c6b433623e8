#pragma once
// The residual of every bundle adjustment (initial, local, global): a world point through T_cw
// onto the ideal pinhole image, minus the undistorted keypoint, weighted by 1 / sigma of its
// pyramid level.
#include <ceres/rotation.h>

#include <Eigen/Core>

#include "core/frame/frame.hpp"

namespace hiveslam::core {

struct ReprojectionError {
  ReprojectionError(const Intrinsics& K, const Eigen::Vector2d& uv, double w) : K(K), uv(uv), w(w) {}

  // pose: the Eigen quaternion coefficients (x, y, z, w) of R_cw, then t_cw; p: world point.
  template <typename T>
  bool operator()(const T* pose, const T* p, T* r) const {
    const T qw[4] = {pose[3], pose[0], pose[1], pose[2]};  // Ceres' order is (w, x, y, z)
    T pc[3];
    ceres::QuaternionRotatePoint(qw, p, pc);
    pc[0] += pose[4];
    pc[1] += pose[5];
    pc[2] += pose[6];
    if (pc[2] <= T(1e-6)) pc[2] = T(1e-6);  // keeps the cost finite; such points are outliers
    r[0] = (T(K.fx) * pc[0] / pc[2] + T(K.cx) - T(uv.x())) * T(w);
    r[1] = (T(K.fy) * pc[1] / pc[2] + T(K.cy) - T(uv.y())) * T(w);
    return true;
  }

  Intrinsics K;
  Eigen::Vector2d uv;
  double w;
};

}  // namespace hiveslam::core
