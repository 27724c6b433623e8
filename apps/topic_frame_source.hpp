#pragma once
// Frames from a ROS 2 sensor_msgs/msg/Image topic, for a TR node fed by a camera driver or by
// `hiveslam play`. Images carry no calibration: it comes from a file (--calibration). The
// stream ends when the publisher goes away or nothing arrives for a while.
#include <chrono>
#include <memory>
#include <string>

#include "communication/dds/image_topic.hpp"
#include "io/frame_source.hpp"

namespace hiveslam::apps {

class TopicFrameSource final : public io::FrameSource {
 public:
  // Throws InputError when the topic name is invalid or no participant can be made.
  TopicFrameSource(int domain, const std::string& ros_topic, io::CameraSettings camera,
                   std::chrono::milliseconds first_wait, std::chrono::milliseconds idle);

  // Drops, with a warning, images it cannot read and images of another size than the
  // calibration's (counted in dropped()).
  std::optional<io::Frame> next() override;
  std::optional<size_t> size() const override { return std::nullopt; }
  const io::CameraSettings& camera() const override { return camera_; }
  const std::optional<io::Trajectory>& groundTruth() const override { return no_truth_; }
  std::string describe() const override;
  uint64_t dropped() const { return (reader_ ? reader_->dropped() : 0) + malformed_; }

 private:
  std::string topic_;
  int domain_;
  // Made by the first next(): a node that first waits for its peers does not take images it
  // cannot track yet (they would be dropped as stale).
  std::unique_ptr<communication::ImageTopicReader> reader_;
  io::CameraSettings camera_;
  std::chrono::milliseconds first_wait_, idle_;
  std::optional<io::Trajectory> no_truth_;
  size_t index_ = 0;
  uint64_t malformed_ = 0;
};

}  // namespace hiveslam::apps
