#pragma once
// Sub-pixel position of a reference patch in another image: Gauss-Newton on the patch's shift
// and an affine brightness change (gain, bias), the reference already warped into the image's
// geometry (geometry/plane_warp does that through a plane).
//
// Why: a corner detector places a corner where its response peaks, and for a blurred, rounded or
// junction corner that place moves with the scale and the slant it is seen at. The same point then
// sits 0.3-0.6 px apart in views that see it differently, and the error is not noise: it follows
// the view, so it bends a map through a turn instead of averaging out. Aligning every view to one
// reference patch measures the same texture location in each: on rendered views of sweep's turn,
// 0.06 px per coordinate from the true projection against 0.16-0.21 px for the same corner found
// again at the same level, 5-30 frames apart (tests/core/patch_alignment_test.cpp).
#include <Eigen/Core>
#include <functional>
#include <opencv2/core.hpp>
#include <optional>
#include <vector>

#include "core/features/image_pyramid.hpp"

namespace hiveslam::features {

// A square patch of 2 half x 2 half samples, row by row; sample (r, c) is the reference's
// brightness at offset (c - half + 0.5, r - half + 0.5) pixels from the patch's centre.
struct Patch {
  int half = 4;
  std::vector<float> values;
  int side() const { return 2 * half; }
  double offset(int i) const { return i - half + 0.5; }
};

// Maps a level-0 pixel of the image searched to the level-0 pixel of the reference image that
// sees the same surface point; nothing where it cannot (the point is behind a camera).
using PixelWarp = std::function<std::optional<Eigen::Vector2d>(const Eigen::Vector2d&)>;

// The reference's appearance as the searched image would see it around `centre` (a pixel of
// `level` of the searched pyramid): each sample goes through `warp` and is read bilinearly from
// the reference level whose pixels best match the warped sample spacing, so that both patches
// carry the same blur. Nothing where a sample leaves the reference image.
std::optional<Patch> sampleWarpedPatch(const ImagePyramid& reference, const ImagePyramid& searched, int level,
                                       cv::Point2d centre, const PixelWarp& warp, int half = 4);

struct PatchAlignmentOptions {
  int max_iterations = 30;
  double converged_px = 1e-3;  // a step this small ends the iterations
  double max_shift_px = 1.0;   // from the start; farther means another corner or none
  double min_gain = 0.5, max_gain = 2.0;
  // The patch must vary in every direction: the weaker eigenvalue of its gradients' structure
  // tensor, as an RMS gradient in grey levels per pixel, at least this (the renders' sensor noise
  // is 2 grey levels; an edge or a flat patch fixes no position along it).
  double min_gradient = 2.0;
};

struct PatchAlignment {
  cv::Point2d position;  // the patch centre's position in the image, pixels
  double gain = 1.0, bias = 0.0;
  int iterations = 0;
};

// Where `patch` lies in `image` (8-bit), searched from `start`; nothing when the search does not
// converge, leaves the image, moves farther than max_shift_px, needs an implausible gain, or the
// patch has too little texture to fix a position (min_gradient).
std::optional<PatchAlignment> alignPatch(const cv::Mat& image, const Patch& patch, cv::Point2d start,
                                         const PatchAlignmentOptions& options = {});

}  // namespace hiveslam::features
