#pragma once
// A surface texture in metric units with a mip pyramid, sampled trilinearly with a few taps
// along the direction of anisotropy so that grazing surfaces neither alias nor smear.
#include <opencv2/core.hpp>
#include <random>
#include <string>
#include <vector>

namespace hiveslam::synth {

class Texture {
 public:
  Texture() = default;
  // level0: 8-bit texture covering (width x height) metres at `density` texels per metre.
  Texture(cv::Mat level0, double density);

  double density() const { return density_; }
  const cv::Mat& level(int i) const { return levels_[static_cast<size_t>(i)]; }
  int levels() const { return static_cast<int>(levels_.size()); }

  // Intensity 0..255 at surface point (u, v) metres. footprint: size of one image pixel on the
  // surface in metres across (minor) and along (major) the direction of anisotropy (du, dv),
  // a unit vector in the (u, v) plane.
  float sample(double u, double v, double minor, double major, double du, double dv) const;
  // Bilinear lookup at a fractional level-0 texel position, on one pyramid level.
  float bilinear(int level, double x0, double y0) const;

 private:
  std::vector<cv::Mat> levels_;
  double density_ = 1.0;
};

// A corner-rich, non-periodic texture: smooth blotches under thousands of random polygons,
// discs and strokes whose sizes span 3 cm to 50 cm.
Texture makeProceduralTexture(double width_m, double height_m, double density, std::mt19937_64& rng);

// A texture tiled (mirrored) from one of `photos` at a random scale and offset, its contrast
// about the mean scaled by `contrast` (below 1: a faded, low-contrast surface).
Texture makePhotoTexture(double width_m, double height_m, double density,
                         const std::vector<cv::Mat>& photos, std::mt19937_64& rng, double contrast = 1.0);

// Paint or laminate: one grey with slow variations of a few percent and a few faint marks
// (scuffs, screw heads, an outline), so that large parts of it hold no corner at all.
Texture makePlainTexture(double width_m, double height_m, double density, double grey, std::mt19937_64& rng);

// Loads the images of a folder as grayscale photos (throws InputError when there are none),
// leaving out those that repeat themselves more than `max_look_alikes` (common/look_alikes.hpp,
// measured at 640 pixels wide): calibration chessboards, logos and drawn shapes, which no real
// room is papered with.
std::vector<cv::Mat> loadPhotos(const std::string& folder, double max_look_alikes = 1.0);

}  // namespace hiveslam::synth
