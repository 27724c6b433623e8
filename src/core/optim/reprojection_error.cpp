#include "core/optim/reprojection_error.hpp"

#include <Eigen/Geometry>
#include <cmath>

#include "core/geometry/skew.hpp"

namespace hiveslam::core {

namespace {

// Below this depth the projection is evaluated at it, as a constant: the cost stays finite and
// such points are outliers anyway (bundle adjustment leaves out those off the camera's axis).
constexpr double kMinDepth = 1e-6;

}  // namespace

bool PoseManifold::Plus(const double* x, const double* delta, double* x_plus_delta) const {
  const Eigen::Map<const Eigen::Quaterniond> q(x);
  const Eigen::Map<const Eigen::Vector3d> d(delta);
  Eigen::Map<Eigen::Quaterniond> q_out(x_plus_delta);
  const double norm = d.norm();
  if (norm > 0.0) {
    const double s = std::sin(norm) / norm;
    q_out = Eigen::Quaterniond(std::cos(norm), s * d.x(), s * d.y(), s * d.z()) * q;
  } else {
    q_out = q;
  }
  for (int i = 0; i < 3; ++i) x_plus_delta[4 + i] = x[4 + i] + delta[3 + i];
  return true;
}

bool PoseManifold::PlusJacobian(const double*, double* jacobian) const {
  Eigen::Map<Eigen::Matrix<double, 7, 6, Eigen::RowMajor>> J(jacobian);
  J.setZero();
  J.topRows<6>().setIdentity();
  return true;
}

bool PoseManifold::Minus(const double* y, const double* x, double* y_minus_x) const {
  const Eigen::Map<const Eigen::Quaterniond> qy(y), qx(x);
  const Eigen::Quaterniond d = qy * qx.conjugate();
  const double vnorm = d.vec().norm();
  const Eigen::Vector3d r = vnorm > 0.0 ? Eigen::Vector3d(std::atan2(vnorm, d.w()) / vnorm * d.vec()) : Eigen::Vector3d::Zero();
  for (int i = 0; i < 3; ++i) {
    y_minus_x[i] = r[i];
    y_minus_x[3 + i] = y[4 + i] - x[4 + i];
  }
  return true;
}

bool PoseManifold::MinusJacobian(const double*, double* jacobian) const {
  Eigen::Map<Eigen::Matrix<double, 6, 7, Eigen::RowMajor>> J(jacobian);
  J.setZero();
  J.leftCols<6>().setIdentity();
  return true;
}

bool ReprojectionError::Evaluate(double const* const* parameters, double* residuals, double** jacobians) const {
  const Eigen::Map<const Eigen::Quaterniond> q(parameters[0]);
  const Eigen::Map<const Eigen::Vector3d> t(parameters[0] + 4), p(parameters[1]);
  const Eigen::Matrix3d R = q.toRotationMatrix();
  const Eigen::Vector3d rp = R * p;
  const Eigen::Vector3d pc = rp + t;
  const bool clamped = pc.z() <= kMinDepth;
  const double z = clamped ? kMinDepth : pc.z();
  const double inv_z = 1.0 / z;
  residuals[0] = (K_.fx * pc.x() * inv_z + K_.cx - uv_.x()) * w_;
  residuals[1] = (K_.fy * pc.y() * inv_z + K_.cy - uv_.y()) * w_;
  if (!jacobians) return true;
  // d residual / d point in the camera frame; the depth's column is zero where it is clamped.
  Eigen::Matrix<double, 2, 3> J_pc;
  J_pc << K_.fx * inv_z, 0.0, clamped ? 0.0 : -K_.fx * pc.x() * inv_z * inv_z,  //
      0.0, K_.fy * inv_z, clamped ? 0.0 : -K_.fy * pc.y() * inv_z * inv_z;
  J_pc *= w_;
  if (jacobians[0]) {
    // Rotating by [cos|d|, sin|d| d/|d|] turns by 2d: d(R p)/dd = -2 [R p]x.
    Eigen::Map<Eigen::Matrix<double, 2, 7, Eigen::RowMajor>> J(jacobians[0]);
    J.leftCols<3>() = -2.0 * J_pc * skew(rp);
    J.block<2, 3>(0, 3) = J_pc;
    J.col(6).setZero();
  }
  if (jacobians[1]) {
    Eigen::Map<Eigen::Matrix<double, 2, 3, Eigen::RowMajor>> J(jacobians[1]);
    J = J_pc * R;
  }
  return true;
}

}  // namespace hiveslam::core
