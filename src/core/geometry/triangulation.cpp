#include "core/geometry/triangulation.hpp"

#include <Eigen/SVD>
#include <cmath>

namespace hiveslam::core {

std::optional<Eigen::Vector3d> intersectRays(const Eigen::Vector3d& r1, const Eigen::Vector3d& r2,
                                             const Eigen::Isometry3d& T_21) {
  Eigen::Matrix<double, 3, 4> P1 = Eigen::Matrix<double, 3, 4>::Zero();
  P1.leftCols<3>().setIdentity();
  const Eigen::Matrix<double, 3, 4> P2 = T_21.matrix().topRows<3>();
  Eigen::Matrix4d A;
  A.row(0) = r1.x() * P1.row(2) - P1.row(0);
  A.row(1) = r1.y() * P1.row(2) - P1.row(1);
  A.row(2) = r2.x() * P2.row(2) - P2.row(0);
  A.row(3) = r2.y() * P2.row(2) - P2.row(1);
  const Eigen::Vector4d X = Eigen::JacobiSVD<Eigen::Matrix4d>(A, Eigen::ComputeFullV).matrixV().col(3);
  if (std::abs(X.w()) < 1e-12) return std::nullopt;
  const Eigen::Vector3d p1 = X.head<3>() / X.w();
  if (!p1.allFinite()) return std::nullopt;
  return p1;
}

std::optional<Eigen::Vector3d> triangulate(const Eigen::Vector3d& r1, const Eigen::Vector3d& r2,
                                           const Eigen::Isometry3d& T_21, double f,
                                           const TriangulationCheck& check, double* parallax_cos) {
  const auto X = intersectRays(r1, r2, T_21);
  if (!X) return std::nullopt;
  const Eigen::Vector3d& p1 = *X;
  const Eigen::Vector3d p2 = T_21 * p1;
  if (p1.z() <= 0 || p2.z() <= 0) return std::nullopt;
  const Eigen::Vector3d c2_in_1 = T_21.inverse().translation();
  const double cos_parallax = p1.normalized().dot((p1 - c2_in_1).normalized());
  if (parallax_cos) *parallax_cos = cos_parallax;
  if (cos_parallax > check.min_parallax_cos) return std::nullopt;
  const double e1 = f * (p1.head<2>() / p1.z() - r1.head<2>()).norm();
  const double e2 = f * (p2.head<2>() / p2.z() - r2.head<2>()).norm();
  if (e1 > check.max_reprojection_px || e2 > check.max_reprojection_px) return std::nullopt;
  return p1;
}

}  // namespace hiveslam::core
