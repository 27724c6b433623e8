#pragma once
#include <array>
#include <vector>

namespace hiveslam::features {

// 256 point pairs (x1, y1, x2, y2) for BRIEF tests inside a patch of radius 13 pixels, drawn
// once from an isotropic Gaussian (BRIEF's sampling strategy G II) with a fixed seed, so every
// node computes the same descriptors. Radius 13 keeps rotated pairs inside the 31x31 patch.
const std::vector<std::array<int, 4>>& briefPattern();

}  // namespace hiveslam::features
