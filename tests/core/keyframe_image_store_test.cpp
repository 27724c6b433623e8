// The keyframe images kept for re-measurement: culled keyframes' images go, recent ones stay.
#include "core/system/keyframe_image_store.hpp"

#include <gtest/gtest.h>

namespace hiveslam::core {
namespace {

TEST(KeyframeImageStore, DropsTheImagesOfGoneKeyframesButNotTheLastKept) {
  KeyframeImageStore store(1 << 20);
  const cv::Mat image(10, 20, CV_8UC1, cv::Scalar(7));
  for (Id id = 1; id <= 5; ++id) store.keep(id, image);
  EXPECT_EQ(store.bytes(), 5u * 200);
  ASSERT_NE(store.pyramid(3, 2, 1.2), nullptr);
  // Keyframes 1 and 2 live; 3, 4 and 5 gone, but 4 and 5 are among the last two kept.
  EXPECT_EQ(store.retain([](Id id) { return id <= 2; }, 2), 1u);
  EXPECT_EQ(store.bytes(), 4u * 200);
  EXPECT_EQ(store.pyramid(3, 2, 1.2), nullptr);
  EXPECT_NE(store.pyramid(4, 2, 1.2), nullptr);
  EXPECT_NE(store.pyramid(1, 2, 1.2), nullptr);
  // Room again for one more.
  store.keep(6, image);
  EXPECT_EQ(store.bytes(), 5u * 200);
}

}  // namespace
}  // namespace hiveslam::core
