#pragma once
// Per-pixel ray casting of a Scene: for every pixel, the nearest surface along its ray, its
// texture filtered to the pixel's footprint, shaded by the scene's lights.
#include <Eigen/Geometry>
#include <opencv2/core.hpp>
#include <vector>

#include "synth/lens.hpp"
#include "synth/scene.hpp"

namespace hiveslam::synth {

// Radiance image (CV_32F, nominally 0..255) seen from camera pose T_wc; optionally the depth
// (CV_32F, metres along the optical axis) of every pixel.
void renderRadiance(const Scene& scene, const RayTable& rays, const Eigen::Isometry3d& T_wc,
                    cv::Mat& radiance, cv::Mat* depth = nullptr);
// A rolling shutter: row v seen from T_wc_rows[v] (one pose per image row).
void renderRadiance(const Scene& scene, const RayTable& rays, const std::vector<Eigen::Isometry3d>& T_wc_rows,
                    cv::Mat& radiance, cv::Mat* depth = nullptr);

}  // namespace hiveslam::synth
