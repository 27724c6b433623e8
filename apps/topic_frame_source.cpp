#include "apps/topic_frame_source.hpp"

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include "apps/image_to_gray.hpp"
#include "common/error.hpp"

namespace hiveslam::apps {

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
    const auto& c = *camera_.camera;
    // Anyone on the domain may publish on the topic: an image tracking cannot read is dropped
    // and counted, and the run goes on.
    if (f.image.empty()) {
      spdlog::warn("{}: dropped a malformed image ({} {}x{}, step {}, {} bytes; mono8, mono16, rgb8, bgr8, rgba8, bgra8 are read)",
                   f.source, image->encoding, image->width, image->height, image->step, image->data.size());
      ++malformed_;
    } else if (f.image.cols != c.width() || f.image.rows != c.height()) {
      spdlog::warn("{}: dropped an image of {}x{}: the calibration is for {}x{}", f.source, f.image.cols, f.image.rows,
                   c.width(), c.height());
      f.image.release();
      ++malformed_;
    }
  }
  return f;
}

std::string TopicFrameSource::describe() const {
  return fmt::format("ROS 2 image topic {} on DDS domain {} ({}x{} {})", topic_, domain_, camera_.camera->width(),
                     camera_.camera->height(), camera_.camera->type());
}

}  // namespace hiveslam::apps
