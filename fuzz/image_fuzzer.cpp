// libFuzzer target: camera images from a ROS 2 topic, which anyone on the domain may publish.
// The input is a sensor_msgs/msg/Image's fields: width, height and step (4 bytes each, little
// endian), one byte choosing the encoding, then the pixel bytes. toGray may return an image or
// an empty one (dropped); a crash or a sanitizer report is a finding.
#include <cstdint>
#include <cstring>

#include "apps/image_to_gray.hpp"

using namespace hiveslam;

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  static const char* const encodings[] = {"mono8", "mono16", "rgb8", "bgr8", "rgba8", "bgra8", "rgb16", ""};
  if (size < 13) return 0;
  communication::CameraImage image;
  std::memcpy(&image.width, data, 4);
  std::memcpy(&image.height, data + 4, 4);
  std::memcpy(&image.step, data + 8, 4);
  image.encoding = encodings[data[12] % 8];
  image.data.assign(data + 13, data + size);
  const cv::Mat gray = apps::toGray(image);
  if (!gray.empty() && (gray.cols != static_cast<int>(image.width) || gray.rows != static_cast<int>(image.height))) __builtin_trap();
  return 0;
}
