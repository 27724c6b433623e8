#include "synth/imaging.hpp"

#include <algorithm>
#include <cmath>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

namespace hiveslam::synth {

Imaging Imaging::realistic() {
  Imaging m;
  m.exposure_s = 0.020;
  m.max_sub_frames = 6;
  m.readout_s = 0.025;
  m.auto_exposure = true;
  m.vignetting = 0.3;
  m.shot_noise = 0.06;
  m.denoise_sigma = 10.0;
  m.jpeg_quality = 85;
  m.focal_error = 0.02;
  m.principal_error_px[0] = 4.0;
  m.principal_error_px[1] = -3.0;
  m.hidden_k1 = 0.05;
  return m;
}

Lens Imaging::trueLens(const Lens& nominal) const {
  Lens l = nominal;
  l.fx *= 1.0 + focal_error;
  l.fy *= 1.0 + 1.2 * focal_error;  // pixels are not quite square either
  l.cx += principal_error_px[0];
  l.cy += principal_error_px[1];
  l.k[0] += hidden_k1;
  return l;
}

cv::Mat Imaging::vignette(int width, int height) const {
  cv::Mat v(height, width, CV_32F, cv::Scalar(1.0f));
  if (vignetting <= 0) return v;
  const double cx = (width - 1) / 2.0, cy = (height - 1) / 2.0, r2max = cx * cx + cy * cy;
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x) {
      const double r2 = ((x - cx) * (x - cx) + (y - cy) * (y - cy)) / r2max;
      // A smooth cos^4-like fall-off that loses `vignetting` at the corners.
      v.at<float>(y, x) = static_cast<float>(1.0 - vignetting * r2 * (0.6 + 0.4 * r2));
    }
  return v;
}

std::vector<double> Imaging::gains(const std::vector<double>& mean_radiance, double fps) const {
  std::vector<double> g(mean_radiance.size(), 1.0);
  if (!auto_exposure || mean_radiance.empty()) return g;
  const double alpha = 1.0 - std::exp(-1.0 / (fps * auto_exposure_tau_s));
  auto wanted = [&](double m) { return std::clamp(target_mean / std::max(m, 1e-3), 0.25, 4.0); };
  double gain = wanted(mean_radiance[0]);
  for (size_t i = 0; i < g.size(); ++i) {
    gain += alpha * (wanted(mean_radiance[i]) - gain);
    g[i] = gain;
  }
  return g;
}

cv::Mat Imaging::develop(const cv::Mat& radiance, double read_noise, uint64_t seed) const {
  cv::Mat signal = radiance.clone();
  if (read_noise > 0 || shot_noise > 0) {
    cv::Mat noise(signal.size(), CV_32F);
    cv::RNG rng(seed);
    rng.fill(noise, cv::RNG::NORMAL, 0.0, 1.0);
    for (int y = 0; y < signal.rows; ++y) {
      float* s = signal.ptr<float>(y);
      const float* n = noise.ptr<float>(y);
      for (int x = 0; x < signal.cols; ++x) {
        const double variance = read_noise * read_noise + shot_noise * std::max(0.0f, s[x]);
        s[x] += static_cast<float>(std::sqrt(variance) * n[x]);
      }
    }
  }
  cv::Mat image;
  signal.convertTo(image, CV_8U);  // rounds and saturates
  if (denoise_sigma > 0) {
    cv::Mat smooth;
    cv::bilateralFilter(image, smooth, 5, denoise_sigma, 2.0);
    image = smooth;
  }
  if (jpeg_quality > 0) {
    std::vector<uchar> bytes;
    cv::imencode(".jpg", image, bytes, {cv::IMWRITE_JPEG_QUALITY, jpeg_quality});
    image = cv::imdecode(bytes, cv::IMREAD_GRAYSCALE);
  }
  return image;
}

}  // namespace hiveslam::synth
