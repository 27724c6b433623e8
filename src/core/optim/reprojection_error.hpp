#pragma once
// The residual of every bundle adjustment (initial, local, global): a world point through T_cw
// onto the ideal pinhole image, minus the undistorted keypoint, weighted by 1 / sigma of its
// pyramid level; with its derivatives written out, and the pose's manifold they are taken on.
//
// The Jacobians are analytic: automatic differentiation carried ten dual numbers through the
// rotation of every observation, the largest single item of a bundle adjustment's time.
#include <ceres/manifold.h>
#include <ceres/sized_cost_function.h>

#include <Eigen/Core>

#include "core/frame/frame.hpp"

namespace hiveslam::core {

// A camera pose as 7 numbers, the Eigen quaternion coefficients (x, y, z, w) of R_cw then t_cw,
// moved on its 6-dof tangent as Ceres' EigenQuaternionManifold times a Euclidean 3-vector moves
// it: q <- [cos|d|, sin|d| d/|d|] * q (d is half the rotation vector, applied on the left),
// t <- t + dt. The same steps as that product manifold.
//
// What differs is the chain rule: Ceres multiplies a cost's Jacobian in the 7 stored numbers
// by PlusJacobian. ReprojectionError gives its Jacobian in the tangent directly (in the first
// six of seven columns, the seventh zero), so PlusJacobian here is the identity on those six:
// the product is the tangent Jacobian, with no derivative in the quaternion's four numbers.
// Only costs written that way may use this manifold.
class PoseManifold final : public ceres::Manifold {
 public:
  int AmbientSize() const override { return 7; }
  int TangentSize() const override { return 6; }
  bool Plus(const double* x, const double* delta, double* x_plus_delta) const override;
  bool PlusJacobian(const double* x, double* jacobian) const override;
  bool Minus(const double* y, const double* x, double* y_minus_x) const override;
  bool MinusJacobian(const double* x, double* jacobian) const override;
};

class ReprojectionError final : public ceres::SizedCostFunction<2, 7, 3> {
 public:
  ReprojectionError(const Intrinsics& K, const Eigen::Vector2d& uv, double w) : K_(K), uv_(uv), w_(w) {}

  // parameters[0]: a pose on PoseManifold; parameters[1]: the world point. jacobians[0] is
  // 2x7 row-major with the tangent Jacobian in its first six columns (see PoseManifold).
  bool Evaluate(double const* const* parameters, double* residuals, double** jacobians) const override;

 private:
  Intrinsics K_;
  Eigen::Vector2d uv_;
  double w_;
};

}  // namespace hiveslam::core
