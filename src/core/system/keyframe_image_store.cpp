#include "core/system/keyframe_image_store.hpp"

namespace hiveslam::core {

void KeyframeImageStore::keep(Id keyframe, const cv::Mat& gray) {
  const size_t size = gray.total() * gray.elemSize();
  std::lock_guard lock(mutex_);
  if (bytes_ + size > budget_ || images_.count(keyframe)) return;
  images_.emplace(keyframe, gray.clone());
  order_.push_back(keyframe);
  bytes_ += size;
}

size_t KeyframeImageStore::retain(const std::function<bool(Id)>& live, size_t recent) {
  std::lock_guard lock(mutex_);
  size_t dropped = 0;
  std::deque<Id> kept;
  for (size_t i = 0; i < order_.size(); ++i) {
    const Id id = order_[i];
    if (i + recent >= order_.size() || live(id)) {
      kept.push_back(id);
      continue;
    }
    const auto it = images_.find(id);
    bytes_ -= it->second.total() * it->second.elemSize();
    images_.erase(it);
    pyramids_.remove_if([id](const auto& p) { return p.first == id; });
    ++dropped;
  }
  order_ = std::move(kept);
  return dropped;
}

bool KeyframeImageStore::empty() const {
  std::lock_guard lock(mutex_);
  return images_.empty();
}

size_t KeyframeImageStore::bytes() const {
  std::lock_guard lock(mutex_);
  return bytes_;
}

std::shared_ptr<const features::ImagePyramid> KeyframeImageStore::pyramid(Id keyframe, int levels, double scale_factor) {
  std::lock_guard lock(mutex_);
  for (auto it = pyramids_.begin(); it != pyramids_.end(); ++it)
    if (it->first == keyframe) {
      pyramids_.splice(pyramids_.begin(), pyramids_, it);
      return it->second;
    }
  const auto image = images_.find(keyframe);
  if (image == images_.end()) return nullptr;
  auto p = std::make_shared<const features::ImagePyramid>(image->second, levels, scale_factor);
  ++built_;
  pyramids_.emplace_front(keyframe, p);
  if (pyramids_.size() > cached_) pyramids_.pop_back();
  return p;
}

void KeyframeImageStore::releasePyramids() {
  std::lock_guard lock(mutex_);
  pyramids_.clear();
}

size_t KeyframeImageStore::pyramidsBuilt() const {
  std::lock_guard lock(mutex_);
  return built_;
}

}  // namespace hiveslam::core
