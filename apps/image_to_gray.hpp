#pragma once
// A ROS 2 camera image as the 8-bit grey image tracking reads.
#include <opencv2/core.hpp>

#include "communication/dds/image_topic.hpp"

namespace hiveslam::apps {

// mono8, mono16, rgb8, bgr8, rgba8 or bgra8 -> 8-bit grey. An empty Mat for any other encoding
// or when the sizes do not add up (a row step shorter than a row or between two 16-bit samples,
// fewer bytes than rows x step, a side no cv::Mat holds): the message is dropped, whoever sent it.
cv::Mat toGray(const communication::CameraImage& image);

}  // namespace hiveslam::apps
