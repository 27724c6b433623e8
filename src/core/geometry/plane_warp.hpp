#pragma once
// The map a plane induces between two views of one camera: a pixel of the first view, its ray
// met with the plane, the point projected into the second view. Distortion included, so it
// works on the pixels corners are found on.
#include <Eigen/Geometry>
#include <optional>

#include "core/camera/camera_model.hpp"

namespace hiveslam::geometry {

class PlaneWarp {
 public:
  // The plane: points X (world) with normal . X = offset.
  PlaneWarp(const camera::CameraModel& camera, const Eigen::Isometry3d& T_from_w, const Eigen::Isometry3d& T_to_w,
            const Eigen::Vector3d& normal, double offset);
  // The plane through `point` with `normal`.
  static PlaneWarp through(const camera::CameraModel& camera, const Eigen::Isometry3d& T_from_w,
                           const Eigen::Isometry3d& T_to_w, const Eigen::Vector3d& point, const Eigen::Vector3d& normal) {
    return PlaneWarp(camera, T_from_w, T_to_w, normal, normal.dot(point));
  }

  // The second view's pixel of the plane point the first view sees at `pixel`; nothing where the
  // ray misses the plane in front of the first camera, or the point cannot be imaged.
  std::optional<Eigen::Vector2d> operator()(const Eigen::Vector2d& pixel) const;

 private:
  const camera::CameraModel& camera_;
  Eigen::Matrix3d R_w_from_;  // rays of the first camera in the world
  Eigen::Vector3d centre_from_;
  Eigen::Isometry3d T_to_w_;
  Eigen::Vector3d normal_;
  double offset_;
};

}  // namespace hiveslam::geometry
