// Camera images from a ROS 2 topic: each encoding tracking reads becomes the same grey image,
// and a message whose sizes do not add up, or whose encoding is another, is dropped (an empty
// image), whoever sent it (fuzz/image_fuzzer.cpp runs the same function under sanitizers).
#include <gtest/gtest.h>

#include <climits>

#include "apps/image_to_gray.hpp"

namespace hiveslam::apps {
namespace {

communication::CameraImage image(const std::string& encoding, uint32_t width, uint32_t height, uint32_t pixel_bytes) {
  communication::CameraImage m;
  m.encoding = encoding;
  m.width = width;
  m.height = height;
  m.step = width * pixel_bytes;
  m.data.assign(static_cast<size_t>(m.step) * height, 200);
  return m;
}

TEST(ImageToGray, EveryEncodingItReadsGivesTheSameGrey) {
  for (const auto& [encoding, bytes] : std::vector<std::pair<std::string, uint32_t>>{
           {"mono8", 1}, {"mono16", 2}, {"rgb8", 3}, {"bgr8", 3}, {"rgba8", 4}, {"bgra8", 4}}) {
    auto m = image(encoding, 8, 4, bytes);
    if (encoding == "mono16")
      for (size_t i = 0; i < m.data.size(); i += 2) m.data[i] = 0;  // little-endian 200 * 256
    const cv::Mat gray = toGray(m);
    ASSERT_EQ(gray.type(), CV_8U) << encoding;
    EXPECT_EQ(gray.cols, 8);
    EXPECT_EQ(gray.rows, 4);
    EXPECT_EQ(gray.at<uint8_t>(3, 7), 200) << encoding;
  }
}

TEST(ImageToGray, MessagesWhoseSizesDoNotAddUpAreDropped) {
  EXPECT_TRUE(toGray(image("rgb16", 8, 4, 6)).empty());  // an encoding it does not read
  EXPECT_TRUE(toGray(image("mono8", 0, 4, 1)).empty());
  auto short_step = image("rgb8", 8, 4, 3);
  short_step.step = 8;  // shorter than a row of 24 bytes
  EXPECT_TRUE(toGray(short_step).empty());
  auto odd_step = image("mono16", 4, 2, 2);  // fuzzer finding: cv::Mat threw, the run ended
  odd_step.step = 9;
  odd_step.data.resize(18);
  EXPECT_TRUE(toGray(odd_step).empty());
  auto short_data = image("mono8", 8, 4, 1);
  short_data.data.pop_back();
  EXPECT_TRUE(toGray(short_data).empty());
  // A side no int holds, with a step and data that would cover it if the sizes wrapped.
  communication::CameraImage huge;
  huge.encoding = "mono8";
  huge.width = 1;
  huge.height = static_cast<uint32_t>(INT_MAX) + 2u;
  huge.step = 0;
  EXPECT_TRUE(toGray(huge).empty());
}

}  // namespace
}  // namespace hiveslam::apps
