#include "apps/image_to_gray.hpp"

#include <climits>

#include <opencv2/imgproc.hpp>

namespace hiveslam::apps {

cv::Mat toGray(const communication::CameraImage& image) {
  const std::string& e = image.encoding;
  const int channels = e == "mono8" ? 1 : e == "mono16" ? 1 : (e == "rgb8" || e == "bgr8") ? 3 : (e == "rgba8" || e == "bgra8") ? 4 : 0;
  if (channels == 0) return {};
  const int depth = e == "mono16" ? CV_16U : CV_8U;
  const size_t pixel = static_cast<size_t>(channels) * (depth == CV_16U ? 2 : 1);
  if (image.width == 0 || image.height == 0 || image.width > INT_MAX || image.height > INT_MAX ||
      image.step < image.width * pixel || image.data.size() < static_cast<size_t>(image.step) * image.height)
    return {};
  // cv::Mat throws on a 16-bit image whose rows start between samples (a fuzzer finding: one
  // mono16 message with a step of 69 bytes ended the run).
  if (depth == CV_16U && image.step % 2 != 0) return {};
  // A view of the message's bytes; every branch below copies out of it.
  const cv::Mat view(static_cast<int>(image.height), static_cast<int>(image.width), CV_MAKETYPE(depth, channels),
                     const_cast<uint8_t*>(image.data.data()), image.step);
  cv::Mat gray;
  if (e == "mono8") gray = view.clone();
  else if (e == "mono16") view.convertTo(gray, CV_8U, 1.0 / 256.0);
  else if (e == "rgb8") cv::cvtColor(view, gray, cv::COLOR_RGB2GRAY);
  else if (e == "bgr8") cv::cvtColor(view, gray, cv::COLOR_BGR2GRAY);
  else if (e == "rgba8") cv::cvtColor(view, gray, cv::COLOR_RGBA2GRAY);
  else cv::cvtColor(view, gray, cv::COLOR_BGRA2GRAY);
  return gray;
}

}  // namespace hiveslam::apps
