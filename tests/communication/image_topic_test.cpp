// ROS 2 image topics over Fast DDS in one process: names, a writer-to-reader round trip, the end
// of a stream when its writer leaves, and a reader that gives up when nobody publishes.
#include <gtest/gtest.h>
#include <unistd.h>

#include <chrono>
#include <thread>

#include "common/error.hpp"
#include "communication/dds/image_topic.hpp"

namespace hiveslam::communication {
namespace {

using namespace std::chrono_literals;

// A domain of its own per test process: parallel test runs do not see each other.
int privateDomain(int offset) { return 150 + (getpid() + offset) % 60; }

CameraImage image(int value, int64_t stamp_ns) {
  CameraImage im;
  im.stamp_ns = stamp_ns;
  im.frame_id = "camera";
  im.width = 64;
  im.height = 48;
  im.step = 64;
  im.encoding = "mono8";
  im.data.assign(64 * 48, static_cast<uint8_t>(value));
  return im;
}

TEST(ImageTopic, RosNamesMapToDdsNames) {
  EXPECT_EQ(ddsTopicName("/camera/image_raw"), "rt/camera/image_raw");
  EXPECT_EQ(ddsTopicName("cam0"), "rt/cam0");
  EXPECT_THROW(ddsTopicName(""), InputError);
  EXPECT_THROW(ddsTopicName("/camera//image"), InputError);
  EXPECT_THROW(ddsTopicName("/camera/"), InputError);
  EXPECT_THROW(ddsTopicName("/my camera"), InputError);
}

TEST(ImageTopic, ImagesArriveIntactAndTheStreamEndsWithItsWriter) {
  const int domain = privateDomain(0);
  ImageTopicReader reader(domain, "/test/image", 8);
  std::vector<CameraImage> got;
  {
    ImageTopicWriter writer(domain, "/test/image");
    ASSERT_TRUE(writer.waitForReaders(1, 5s));
    ASSERT_TRUE(reader.waitForWriter(5s));
    for (int k = 0; k < 3; ++k) {
      writer.write(image(10 * (k + 1), 1'000'000'000LL * (k + 1) + 5));
      std::this_thread::sleep_for(20ms);
    }
    for (int k = 0; k < 3; ++k)
      if (auto im = reader.next(5s, 5s)) got.push_back(std::move(*im));
  }
  ASSERT_EQ(got.size(), 3u);
  for (int k = 0; k < 3; ++k) {
    EXPECT_EQ(got[static_cast<size_t>(k)].stamp_ns, 1'000'000'000LL * (k + 1) + 5);
    EXPECT_EQ(got[static_cast<size_t>(k)].encoding, "mono8");
    EXPECT_EQ(got[static_cast<size_t>(k)].width, 64u);
    EXPECT_EQ(got[static_cast<size_t>(k)].data, image(10 * (k + 1), 0).data);
  }
  // The writer is gone: the stream is over well before the idle time-out.
  const auto t0 = std::chrono::steady_clock::now();
  EXPECT_FALSE(reader.next(20s, 20s).has_value());
  EXPECT_LT(std::chrono::steady_clock::now() - t0, 10s);
}

TEST(ImageTopic, ASlowReaderKeepsTheNewestImages) {
  const int domain = privateDomain(1);
  ImageTopicReader reader(domain, "/test/burst", 2);
  ImageTopicWriter writer(domain, "/test/burst");
  ASSERT_TRUE(writer.waitForReaders(1, 5s));
  ASSERT_TRUE(reader.waitForWriter(5s));
  for (int k = 0; k < 6; ++k) {
    writer.write(image(k, k + 1));
    std::this_thread::sleep_for(10ms);
  }
  std::this_thread::sleep_for(200ms);
  // The two newest of six, then nothing.
  auto first = reader.next(5s, 5s), second = reader.next(5s, 5s);
  ASSERT_TRUE(first.has_value() && second.has_value());
  EXPECT_EQ(first->stamp_ns, 5);
  EXPECT_EQ(second->stamp_ns, 6);
  EXPECT_FALSE(reader.next(200ms, 200ms).has_value());
}

TEST(ImageTopic, AReaderWithNoPublisherGivesUp) {
  ImageTopicReader reader(privateDomain(2), "/test/nobody");
  const auto t0 = std::chrono::steady_clock::now();
  EXPECT_FALSE(reader.next(300ms, 300ms).has_value());
  EXPECT_LT(std::chrono::steady_clock::now() - t0, 3s);
}

}  // namespace
}  // namespace hiveslam::communication
