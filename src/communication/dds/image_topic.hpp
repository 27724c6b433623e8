#pragma once
// ROS 2 camera images over DDS: sensor_msgs/msg/Image on a ROS topic (DDS topic "rt/<name>",
// type "sensor_msgs::msg::dds_::Image_"), what `hiveslam play` publishes, the way the paper fed
// rosbags to TR, and what a TR node reads from a ROS 2 camera driver.
//
// Each end owns its participant. The reader is BEST_EFFORT so that it matches both reliable
// writers and the best-effort "sensor data" writers of camera drivers, and keeps only the
// newest few images: a camera does not wait for a slow tracker.
#include <chrono>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace hiveslam::communication {

struct CameraImage {
  int64_t stamp_ns = 0;  // header.stamp
  std::string frame_id;
  uint32_t width = 0, height = 0, step = 0;
  std::string encoding;  // "mono8", "bgr8", "rgb8", ...
  std::vector<uint8_t> data;
};

// "/camera/image_raw" -> "rt/camera/image_raw". Throws InputError on a name ROS 2 would refuse
// (empty, with spaces, "//", ending in "/").
std::string ddsTopicName(const std::string& ros_topic);

class ImageTopicWriter {
 public:
  ImageTopicWriter(int domain, const std::string& ros_topic);
  ~ImageTopicWriter();
  ImageTopicWriter(const ImageTopicWriter&) = delete;
  ImageTopicWriter& operator=(const ImageTopicWriter&) = delete;

  // Readers matched now.
  int readers() const;
  // Waits until at least `count` readers have matched, at most `timeout`.
  bool waitForReaders(int count, std::chrono::milliseconds timeout) const;
  void write(const CameraImage& image);

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

class ImageTopicReader {
 public:
  // Keeps at most `depth` images waiting; older ones are dropped (and counted).
  ImageTopicReader(int domain, const std::string& ros_topic, size_t depth = 2);
  ~ImageTopicReader();
  ImageTopicReader(const ImageTopicReader&) = delete;
  ImageTopicReader& operator=(const ImageTopicReader&) = delete;

  // The next image, or nullopt when the stream is over: every writer that had matched went
  // away, or nothing arrived for `idle` (before the first image: for `first`).
  std::optional<CameraImage> next(std::chrono::milliseconds first, std::chrono::milliseconds idle);
  // Images dropped because the reader was behind.
  uint64_t dropped() const;
  // Whether a writer has matched within `timeout`. Discovery is not symmetric: a writer can
  // see this reader before this reader sees it, and best-effort images it sends meanwhile are
  // lost (harmless in a stream; a test that counts images waits for both sides).
  bool waitForWriter(std::chrono::milliseconds timeout);

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace hiveslam::communication
