#pragma once
// Kannala-Brandt equidistant fisheye model (TUM-VI, OpenCV fisheye):
// theta_d = theta (1 + k1 theta^2 + k2 theta^4 + k3 theta^6 + k4 theta^8).
#include <array>

#include "core/camera/camera_model.hpp"

namespace hiveslam::camera {

class KannalaBrandt final : public CameraModel {
 public:
  KannalaBrandt(int width, int height, double fx, double fy, double cx, double cy,
                const std::vector<double>& k);

  std::string type() const override { return "kannala-brandt"; }
  std::vector<double> parameters() const override;
  std::unique_ptr<CameraModel> clone() const override;
  bool project(const Eigen::Vector3d& p_c, Eigen::Vector2d& uv) const override;
  Eigen::Vector3d unproject(const Eigen::Vector2d& uv) const override;

 private:
  double thetaD(double theta) const;
  std::array<double, 4> k_{};
  double max_theta_;  // beyond it theta_d stops growing and the model is not invertible
};

}  // namespace hiveslam::camera
