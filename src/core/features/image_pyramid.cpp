#include "core/features/image_pyramid.hpp"

#include <cmath>
#include <limits>
#include <opencv2/imgproc.hpp>

namespace hiveslam::features {

ImagePyramid::ImagePyramid(const cv::Mat& gray, int levels, double scale_factor) : scale_factor_(scale_factor) {
  CV_Assert(gray.type() == CV_8UC1);
  double s = 1.0;
  for (int l = 0; l < levels; ++l, s *= scale_factor) {
    const cv::Size size = pyramidLevelSize(gray.size(), s);
    if (size.width < 2 || size.height < 2) break;
    cv::Mat m;
    if (l == 0) m = gray;
    else cv::resize(gray, m, size, 0, 0, cv::INTER_LINEAR);
    levels_.push_back(m);
    ratio_.emplace_back(static_cast<double>(gray.cols) / size.width, static_cast<double>(gray.rows) / size.height);
  }
}

cv::Point2d ImagePyramid::toLevel(int l, cv::Point2d p) const {
  const cv::Point2d& r = ratio_[static_cast<size_t>(l)];
  return {(p.x + 0.5) / r.x - 0.5, (p.y + 0.5) / r.y - 0.5};
}

cv::Point2d ImagePyramid::toLevel0(int l, cv::Point2d p) const {
  const cv::Point2d& r = ratio_[static_cast<size_t>(l)];
  return {(p.x + 0.5) * r.x - 0.5, (p.y + 0.5) * r.y - 0.5};
}

float sampleBilinear(const cv::Mat& gray, double x, double y) {
  const double fx0 = std::floor(x), fy0 = std::floor(y);
  const int ix = static_cast<int>(fx0), iy = static_cast<int>(fy0);
  if (ix < 0 || iy < 0 || ix >= gray.cols - 1 || iy >= gray.rows - 1) return std::numeric_limits<float>::quiet_NaN();
  const double fx = x - fx0, fy = y - fy0;
  const uchar* r0 = gray.ptr<uchar>(iy);
  const uchar* r1 = gray.ptr<uchar>(iy + 1);
  const double top = r0[ix] + fx * (r0[ix + 1] - r0[ix]);
  const double bottom = r1[ix] + fx * (r1[ix + 1] - r1[ix]);
  return static_cast<float>(top + fy * (bottom - top));
}

}  // namespace hiveslam::features
