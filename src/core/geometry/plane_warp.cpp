#include "core/geometry/plane_warp.hpp"

#include <cmath>

namespace hiveslam::geometry {

PlaneWarp::PlaneWarp(const camera::CameraModel& camera, const Eigen::Isometry3d& T_from_w, const Eigen::Isometry3d& T_to_w,
                     const Eigen::Vector3d& normal, double offset)
    : camera_(camera),
      R_w_from_(T_from_w.linear().transpose()),
      centre_from_(T_from_w.inverse().translation()),
      T_to_w_(T_to_w),
      normal_(normal),
      offset_(offset) {}

std::optional<Eigen::Vector2d> PlaneWarp::operator()(const Eigen::Vector2d& pixel) const {
  const Eigen::Vector3d ray = R_w_from_ * camera_.unproject(pixel);
  const double along = normal_.dot(ray);
  if (std::abs(along) < 1e-9) return std::nullopt;  // the ray runs along the plane
  const double t = (offset_ - normal_.dot(centre_from_)) / along;
  if (t <= 0) return std::nullopt;
  Eigen::Vector2d out;
  if (!camera_.project(T_to_w_ * (centre_from_ + t * ray), out)) return std::nullopt;
  return out;
}

}  // namespace hiveslam::geometry
