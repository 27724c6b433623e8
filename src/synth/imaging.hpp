#pragma once
// What a real camera does to the light between the scene and the file, for the realistic
// renders (SequenceOptions::realistic): a lens that is not the nominal one, an exposure long
// enough to blur, a rolling shutter, auto exposure that follows the scene's brightness with a
// lag, vignetting, shot noise, the camera's denoising and JPEG compression.
#include <opencv2/core.hpp>
#include <vector>

#include "synth/lens.hpp"

namespace hiveslam::synth {

struct Imaging {
  double exposure_s = 0.010;    // motion blur: the exposure the sub-frames average over
  int max_sub_frames = 5;       // sub-frames at most; fewer where the view hardly moves
  double readout_s = 0.0;       // rolling shutter: first to last row (0: global shutter)
  bool auto_exposure = false;   // gain follows the mean brightness, time constant below
  double auto_exposure_tau_s = 0.3;
  double target_mean = 110.0;   // the grey level auto exposure aims at
  double vignetting = 0.0;      // brightness lost at the image corners (0.3: 30%)
  double shot_noise = 0.0;      // noise variance per grey level of signal (photon noise)
  // The camera's own denoising before JPEG, as every phone and webcam pipeline has: an
  // edge-preserving (bilateral) filter that smooths differences under about this many grey
  // levels (0: none). Without it a plain wall of the realistic renders held 5-7x the weak
  // corners of phone_room_droidcam's (`hiveslam info --image-stats`).
  double denoise_sigma = 0.0;
  int jpeg_quality = 0;         // 0: no compression
  // The camera's true lens, against the nominal one written to sensor.yaml: focal lengths off
  // by this share, the principal point by these pixels, and a radial term nobody wrote down.
  double focal_error = 0.0;
  double principal_error_px[2] = {0.0, 0.0};
  double hidden_k1 = 0.0;

  // A hand-held consumer camera indoors (a webcam or a phone streaming 640x480): 20 ms
  // exposure, 25 ms readout, auto exposure, 30% vignetting, denoising, JPEG at 85, a lens 2% longer than
  // its nominal focal length with a 4 px offset and an unwritten k1 of 0.05.
  static Imaging realistic();

  // The lens the images are made with, given the nominal one.
  Lens trueLens(const Lens& nominal) const;
  // Brightness factor per pixel (CV_32F, 1 at the centre).
  cv::Mat vignette(int width, int height) const;
  // Gains per frame from each frame's mean radiance (at unit gain): a first-order lag towards
  // target_mean / mean, within 0.25-4. All 1 without auto exposure.
  std::vector<double> gains(const std::vector<double>& mean_radiance, double fps) const;
  // From gained radiance to the 8-bit image: noise (read sigma `read_noise`, plus shot noise),
  // rounding and saturation, denoising, then JPEG. `seed` makes the noise repeatable per frame.
  cv::Mat develop(const cv::Mat& radiance, double read_noise, uint64_t seed) const;
};

}  // namespace hiveslam::synth
