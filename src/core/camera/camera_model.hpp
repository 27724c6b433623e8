#pragma once
// A calibrated monocular camera: maps points in the camera frame (x right, y down, z forward)
// to distorted pixel coordinates and back. The SLAM core works on bearings and on
// undistorted normalized coordinates, so every model offers both directions.
#include <Eigen/Core>
#include <memory>
#include <string>
#include <vector>

namespace hiveslam::camera {

class CameraModel {
 public:
  CameraModel(int width, int height, double fx, double fy, double cx, double cy)
      : width_(width), height_(height), fx_(fx), fy_(fy), cx_(cx), cy_(cy) {}
  virtual ~CameraModel() = default;

  // "pinhole-radtan" or "kannala-brandt".
  virtual std::string type() const = 0;
  // fx fy cx cy followed by the distortion coefficients of the model.
  virtual std::vector<double> parameters() const = 0;
  virtual std::unique_ptr<CameraModel> clone() const = 0;

  // Pixel of a point given in the camera frame; false when the point cannot be imaged
  // (behind a pinhole camera, or outside the valid angle of a fisheye).
  virtual bool project(const Eigen::Vector3d& p_c, Eigen::Vector2d& uv) const = 0;
  // Unit bearing of a pixel (inverse of project up to scale).
  virtual Eigen::Vector3d unproject(const Eigen::Vector2d& uv) const = 0;

  // Focal lengths and principal point, the linear part of every model.
  double fx() const { return fx_; }
  double fy() const { return fy_; }
  double cx() const { return cx_; }
  double cy() const { return cy_; }

  int width() const { return width_; }
  int height() const { return height_; }
  bool inImage(const Eigen::Vector2d& uv, double border = 0.0) const {
    return uv.x() >= border && uv.y() >= border && uv.x() <= width_ - 1 - border &&
           uv.y() <= height_ - 1 - border;
  }

 protected:
  int width_;
  int height_;
  double fx_, fy_, cx_, cy_;
};

}  // namespace hiveslam::camera
