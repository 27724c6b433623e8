#pragma once
// Linear (DLT) triangulation of one point seen in two views, with the checks a SLAM map needs
// before it trusts the point: in front of both cameras, small reprojection error, enough
// parallax.
#include <Eigen/Geometry>
#include <optional>

namespace hiveslam::core {

struct TriangulationCheck {
  double max_reprojection_px = 2.0;  // in each view, on the ideal pinhole image
  double min_parallax_cos = 0.99998; // cosine of the angle between the two viewing rays
};

// The linear (DLT) intersection of two rays, in the frame of view 1, before any check: what
// the two views say about the point, in front of the cameras or not. nullopt at infinity.
std::optional<Eigen::Vector3d> intersectRays(const Eigen::Vector3d& r1, const Eigen::Vector3d& r2,
                                             const Eigen::Isometry3d& T_21);

// Point in the frame of view 1. r1, r2: rays (x/z, y/z, 1) of the observations; T_21 maps
// view-1 coordinates to view 2; f: focal length in pixels (for the pixel error test).
// Returns nullopt when a check fails; `parallax_cos` receives the ray angle cosine.
std::optional<Eigen::Vector3d> triangulate(const Eigen::Vector3d& r1, const Eigen::Vector3d& r2,
                                           const Eigen::Isometry3d& T_21, double f,
                                           const TriangulationCheck& check, double* parallax_cos = nullptr);

}  // namespace hiveslam::core
