#pragma once
// Matches for two-view initialization: no map yet, so each keypoint of the first frame looks
// for a keypoint of the same pyramid level near the same pixel in the second frame.
#include <vector>

#include "core/frame/frame.hpp"

namespace hiveslam::core {

struct InitialMatchOptions {
  double radius = 100.0;   // pixels around the first frame's position
  int max_distance = 50;   // Hamming
  double ratio = 0.9;      // best / second best
  bool check_rotation = true;
};

// For each keypoint of f1, the index of its match in f2 or -1. One-to-one. `around`, when
// given, holds per keypoint of f1 where to search in f2 (where it was last seen).
std::vector<int> matchForInitialization(const Frame& f1, const Frame& f2, const InitialMatchOptions& options = {},
                                        const std::vector<Eigen::Vector2d>* around = nullptr);

}  // namespace hiveslam::core
