#include "apps/topic_frame_source.hpp"

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <opencv2/imgproc.hpp>

#include "common/error.hpp"

namespace hiveslam::apps {

cv::Mat toGray(const communication::CameraImage& image) {
  const std::string& e = image.encoding;
  const int channels = e == "mono8" ? 1 : e == "mono16" ? 1 : (e == "rgb8" || e == "bgr8") ? 3 : (e == "rgba8" || e == "bgra8") ? 4 : 0;
  if (channels == 0) throw InputError("image encoding '" + e + "' is not supported (mono8, mono16, rgb8, bgr8, rgba8, bgra8)");
  const int depth = e == "mono16" ? CV_16U : CV_8U;
  const size_t pixel = static_cast<size_t>(channels) * (depth == CV_16U ? 2 : 1);
  if (image.width == 0 || image.height == 0 || image.step < image.width * pixel ||
      image.data.size() < static_cast<size_t>(image.step) * image.height)
    return {};
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

TopicFrameSource::TopicFrameSource(int domain, const std::string& ros_topic, io::CameraSettings camera,
                                   std::chrono::milliseconds first_wait, std::chrono::milliseconds idle)
    : topic_(ros_topic), domain_(domain), camera_(std::move(camera)), first_wait_(first_wait), idle_(idle) {
  communication::ddsTopicName(ros_topic);  // a bad name is refused now, not at the first frame
  if (domain < 0 || domain > 232) throw InputError("DDS domain must be 0-232");
}

std::optional<io::Frame> TopicFrameSource::next() {
  io::Frame f;
  if (!reader_) reader_ = std::make_unique<communication::ImageTopicReader>(domain_, topic_);
  while (f.image.empty()) {
    auto image = reader_->next(first_wait_, idle_);
    if (!image) return std::nullopt;
    f.index = index_++;
    f.timestamp = static_cast<double>(image->stamp_ns) * 1e-9;
    f.image = toGray(*image);
    f.source = fmt::format("{} #{}", topic_, f.index);
    if (f.image.empty())
      spdlog::warn("{}: dropped a malformed image ({}x{}, step {}, {} bytes)", f.source, image->width,
                   image->height, image->step, image->data.size());
  }
  const auto& c = *camera_.camera;
  if (f.image.cols != c.width() || f.image.rows != c.height())
    throw InputError(fmt::format("{}: image is {}x{} but the calibration is for {}x{}", f.source, f.image.cols,
                                 f.image.rows, c.width(), c.height()));
  return f;
}

std::string TopicFrameSource::describe() const {
  return fmt::format("ROS 2 image topic {} on DDS domain {} ({}x{} {})", topic_, domain_, camera_.camera->width(),
                     camera_.camera->height(), camera_.camera->type());
}

}  // namespace hiveslam::apps
