#pragma once
// The keyframe database: an inverted index from vocabulary words to the keyframes whose images
// contain them, over every map of the atlas. A query scores only the keyframes that share
// words with the query, which keeps place recognition and relocalization fast as maps grow.
//
// Locking: the database has its own mutex and touches nothing but the keyframes' immutable
// bag-of-words vectors, so it may be called with or without a map's mutex held (order: map
// mutex, then database mutex).
#include <mutex>
#include <unordered_map>
#include <unordered_set>
#include <vector>

#include "core/map/keyframe.hpp"
#include "core/place/bow_vector.hpp"

namespace hiveslam::core {

class Map;

struct PlaceCandidate {
  KeyFrame* keyframe = nullptr;
  Map* map = nullptr;
  int common_words = 0;
  double score = 0;
};

class KeyframeDatabase {
 public:
  void add(KeyFrame* kf, Map* map);
  void erase(KeyFrame* kf);
  // Every keyframe of `from` now belongs to `to` (after a map merge).
  void moveMap(Map* from, Map* to);
  // Keyframes sharing words with `bow`, those not in `exclude`, with at least 80% of the best
  // candidate's shared words, scored (L1), best first.
  std::vector<PlaceCandidate> query(const place::BowVector& bow, const std::unordered_set<Id>& exclude) const;
  size_t size() const;

 private:
  mutable std::mutex mutex_;
  // Per word, the keyframes holding it, in the order they came. Vectors: an erase walks a
  // contiguous list (a linked list's walk was a tenth of TR's map handling).
  std::unordered_map<place::WordId, std::vector<KeyFrame*>> index_;
  std::unordered_map<KeyFrame*, Map*> map_of_;
};

}  // namespace hiveslam::core
