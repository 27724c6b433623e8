#include "core/camera/kannala_brandt.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <stdexcept>

namespace hiveslam::camera {

KannalaBrandt::KannalaBrandt(int width, int height, double fx, double fy, double cx, double cy,
                             const std::vector<double>& k)
    : CameraModel(width, height, fx, fy, cx, cy) {
  if (k.size() != 4)
    throw std::invalid_argument("Kannala-Brandt distortion needs 4 coefficients, got " +
                                std::to_string(k.size()));
  for (size_t i = 0; i < 4; ++i) k_[i] = k[i];
  // Largest angle up to which theta_d is monotonic (checked in small steps up to 180 deg).
  max_theta_ = std::numbers::pi;
  double prev = 0.0;
  for (double th = 1e-3; th <= std::numbers::pi; th += 1e-3) {
    const double td = thetaD(th);
    if (td <= prev) {
      max_theta_ = th - 1e-3;
      break;
    }
    prev = td;
  }
}

double KannalaBrandt::thetaD(double t) const {
  const double t2 = t * t;
  return t * (1.0 + t2 * (k_[0] + t2 * (k_[1] + t2 * (k_[2] + t2 * k_[3]))));
}

std::vector<double> KannalaBrandt::parameters() const {
  return {fx_, fy_, cx_, cy_, k_[0], k_[1], k_[2], k_[3]};
}

std::unique_ptr<CameraModel> KannalaBrandt::clone() const {
  return std::make_unique<KannalaBrandt>(*this);
}

bool KannalaBrandt::project(const Eigen::Vector3d& p, Eigen::Vector2d& uv) const {
  const double r = std::hypot(p.x(), p.y());
  const double theta = std::atan2(r, p.z());
  if (theta > max_theta_ || p.norm() < 1e-12) return false;
  const double td = thetaD(theta);
  // On the optical axis the direction is undefined but the pixel is the principal point.
  const double s = r > 1e-12 ? td / r : 1.0 / std::max(p.z(), 1e-12);
  uv = {fx_ * s * p.x() + cx_, fy_ * s * p.y() + cy_};
  return true;
}

Eigen::Vector3d KannalaBrandt::unproject(const Eigen::Vector2d& uv) const {
  const double mx = (uv.x() - cx_) / fx_, my = (uv.y() - cy_) / fy_;
  const double td = std::hypot(mx, my);
  if (td < 1e-12) return {0.0, 0.0, 1.0};
  double th = std::min(td, max_theta_);
  for (int it = 0; it < 30; ++it) {  // Newton on thetaD(th) = td
    const double t2 = th * th;
    const double f = thetaD(th) - td;
    const double df =
        1.0 + t2 * (3.0 * k_[0] + t2 * (5.0 * k_[1] + t2 * (7.0 * k_[2] + t2 * 9.0 * k_[3])));
    const double step = f / df;
    th = std::clamp(th - step, 0.0, max_theta_);
    if (std::abs(step) < 1e-14) break;
  }
  const double s = std::sin(th) / td;
  return {mx * s, my * s, std::cos(th)};
}

}  // namespace hiveslam::camera
