#include "core/camera/pinhole_radtan.hpp"

#include <Eigen/Dense>
#include <stdexcept>

namespace hiveslam::camera {

PinholeRadTan::PinholeRadTan(int width, int height, double fx, double fy, double cx, double cy,
                             const std::vector<double>& distortion)
    : CameraModel(width, height, fx, fy, cx, cy) {
  if (!distortion.empty() && distortion.size() != 4 && distortion.size() != 5)
    throw std::invalid_argument("radial-tangential distortion needs 4 or 5 coefficients, got " +
                                std::to_string(distortion.size()));
  for (size_t i = 0; i < distortion.size(); ++i) d_[i] = distortion[i];
}

std::vector<double> PinholeRadTan::parameters() const {
  return {fx_, fy_, cx_, cy_, d_[0], d_[1], d_[2], d_[3], d_[4]};
}

std::unique_ptr<CameraModel> PinholeRadTan::clone() const {
  return std::make_unique<PinholeRadTan>(*this);
}

bool PinholeRadTan::hasDistortion() const {
  for (double k : d_)
    if (k != 0.0) return true;
  return false;
}

Eigen::Vector2d PinholeRadTan::distort(const Eigen::Vector2d& xn) const {
  const double x = xn.x(), y = xn.y();
  const double r2 = x * x + y * y;
  const double radial = 1.0 + r2 * (d_[0] + r2 * (d_[1] + r2 * d_[4]));
  return {x * radial + 2.0 * d_[2] * x * y + d_[3] * (r2 + 2.0 * x * x),
          y * radial + d_[2] * (r2 + 2.0 * y * y) + 2.0 * d_[3] * x * y};
}

Eigen::Vector2d PinholeRadTan::undistort(const Eigen::Vector2d& xd) const {
  if (!hasDistortion()) return xd;
  Eigen::Vector2d x = xd;
  for (int it = 0; it < 30; ++it) {
    // Numerical Jacobian is enough here: the residual is smooth and the start is close.
    const Eigen::Vector2d r = distort(x) - xd;
    if (r.squaredNorm() < 1e-26) break;
    constexpr double h = 1e-7;
    Eigen::Matrix2d J;
    J.col(0) = (distort(x + Eigen::Vector2d(h, 0)) - distort(x)) / h;
    J.col(1) = (distort(x + Eigen::Vector2d(0, h)) - distort(x)) / h;
    x -= J.partialPivLu().solve(r);
  }
  return x;
}

bool PinholeRadTan::project(const Eigen::Vector3d& p_c, Eigen::Vector2d& uv) const {
  if (p_c.z() <= 1e-9) return false;
  const Eigen::Vector2d xd = distort(p_c.head<2>() / p_c.z());
  uv = {fx_ * xd.x() + cx_, fy_ * xd.y() + cy_};
  return true;
}

Eigen::Vector3d PinholeRadTan::unproject(const Eigen::Vector2d& uv) const {
  const Eigen::Vector2d xn = undistort({(uv.x() - cx_) / fx_, (uv.y() - cy_) / fy_});
  return Eigen::Vector3d(xn.x(), xn.y(), 1.0).normalized();
}

}  // namespace hiveslam::camera
