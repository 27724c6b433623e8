#pragma once
// Pinhole camera with radial-tangential (Brown-Conrady) distortion, as in EuRoC's sensor.yaml
// and OpenCV: k1 k2 p1 p2 [k3].
#include <array>

#include "core/camera/camera_model.hpp"

namespace hiveslam::camera {

class PinholeRadTan final : public CameraModel {
 public:
  // distortion: empty, 4 (k1 k2 p1 p2) or 5 (k1 k2 p1 p2 k3) coefficients.
  PinholeRadTan(int width, int height, double fx, double fy, double cx, double cy,
                const std::vector<double>& distortion = {});

  std::string type() const override { return "pinhole-radtan"; }
  std::vector<double> parameters() const override;
  std::unique_ptr<CameraModel> clone() const override;
  bool project(const Eigen::Vector3d& p_c, Eigen::Vector2d& uv) const override;
  Eigen::Vector3d unproject(const Eigen::Vector2d& uv) const override;

  // Distortion applied to normalized coordinates (x/z, y/z).
  Eigen::Vector2d distort(const Eigen::Vector2d& xn) const;
  // Inverse of distort by Gauss-Newton; exact to ~1e-12 inside the image.
  Eigen::Vector2d undistort(const Eigen::Vector2d& xd) const;
  bool hasDistortion() const;

 private:
  std::array<double, 5> d_{};  // k1 k2 p1 p2 k3
};

}  // namespace hiveslam::camera
