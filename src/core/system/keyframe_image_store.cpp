#include "core/system/keyframe_image_store.hpp"

namespace hiveslam::core {

void KeyframeImageStore::keep(Id keyframe, const cv::Mat& gray) {
  const size_t size = gray.total() * gray.elemSize();
  std::lock_guard lock(mutex_);
  if (bytes_ + size > budget_ || images_.count(keyframe)) return;
  images_.emplace(keyframe, gray.clone());
  bytes_ += size;
}

bool KeyframeImageStore::empty() const {
  std::lock_guard lock(mutex_);
  return images_.empty();
}

size_t KeyframeImageStore::bytes() const {
  std::lock_guard lock(mutex_);
  return bytes_;
}

const features::ImagePyramid* KeyframeImageStore::pyramid(Id keyframe, int levels, double scale_factor) {
  std::lock_guard lock(mutex_);
  if (const auto it = pyramids_.find(keyframe); it != pyramids_.end()) return &it->second;
  const auto image = images_.find(keyframe);
  if (image == images_.end()) return nullptr;
  return &pyramids_.emplace(keyframe, features::ImagePyramid(image->second, levels, scale_factor)).first->second;
}

void KeyframeImageStore::releasePyramids() {
  std::lock_guard lock(mutex_);
  pyramids_.clear();
}

}  // namespace hiveslam::core
