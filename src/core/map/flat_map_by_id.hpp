#pragma once
// A map from keyframe (or map point) pointers to a small value, kept as one vector sorted by
// the key's id: the order std::map<K*, V, ById> iterates in, so every loop over it visits the
// same elements in the same order as before (the sequential mode's promise), in contiguous
// memory. A point's observers and a keyframe's covisible neighbours are a few to a few dozen
// entries, walked far more often than changed: covisibility updates walk every observer of
// every point of a keyframe, and the tree's node-to-node steps were a quarter of a replica's
// map-handler thread.
//
// Unlike std::map, inserting or erasing moves later entries: iterators and references into
// the container do not survive a change to it.
#include <algorithm>
#include <stdexcept>
#include <utility>
#include <vector>

namespace hiveslam::core {

template <typename K, typename V>
class FlatMapById {
 public:
  using value_type = std::pair<K*, V>;
  using iterator = typename std::vector<value_type>::iterator;
  using const_iterator = typename std::vector<value_type>::const_iterator;

  iterator begin() { return items_.begin(); }
  iterator end() { return items_.end(); }
  const_iterator begin() const { return items_.begin(); }
  const_iterator end() const { return items_.end(); }
  size_t size() const { return items_.size(); }
  bool empty() const { return items_.empty(); }
  void clear() { items_.clear(); }
  void reserve(size_t n) { items_.reserve(n); }

  iterator find(const K* key) {
    auto it = lowerBound(key);
    return it != items_.end() && it->first->id == key->id ? it : items_.end();
  }
  const_iterator find(const K* key) const { return const_cast<FlatMapById*>(this)->find(key); }
  size_t count(const K* key) const { return find(key) != end() ? 1 : 0; }

  const V& at(const K* key) const {
    auto it = find(key);
    if (it == end()) throw std::out_of_range("FlatMapById::at: no such key");
    return it->second;
  }
  V& operator[](K* key) {
    auto it = lowerBound(key);
    if (it == items_.end() || it->first->id != key->id) it = items_.insert(it, value_type(key, V{}));
    return it->second;
  }

  size_t erase(const K* key) {
    auto it = find(key);
    if (it == items_.end()) return 0;
    items_.erase(it);
    return 1;
  }
  iterator erase(const_iterator it) { return items_.erase(it); }

 private:
  iterator lowerBound(const K* key) {
    return std::lower_bound(items_.begin(), items_.end(), key->id,
                            [](const value_type& v, const auto& id) { return v.first->id < id; });
  }

  std::vector<value_type> items_;
};

}  // namespace hiveslam::core
