#pragma once
// Named suites of sequences that later issues measure accuracy on.
#include <string>
#include <vector>

#include "synth/sequence.hpp"

namespace hiveslam::synth {

struct SuiteEntry {
  std::string name;  // folder name under the suite's output folder
  SequenceOptions options;
};

// "standard": figure8 (exposure changes), blackout (a blank transit), sweep (EuRoC-like lens
// distortion; no revisit), bigloop (a wide lap close to the walls, with the drift a loop
// closure has to remove); all 752x480 at 20 fps with sensor noise.
// "realistic": four hand-held walks (handheld1-4, 1000-1200 frames, each returning past its
// start) through furnished rooms, 640x480 at 30 fps, with every imaging effect of a consumer
// camera (SequenceOptions::realistic); textured from `textures`, by default Debian's opencv-doc
// photos where installed (procedural textures otherwise).
std::vector<SuiteEntry> suite(const std::string& name, const std::string& textures = "");

// Where Debian's opencv-doc package keeps its example photos.
extern const char* const kDebianPhotos;

}  // namespace hiveslam::synth
