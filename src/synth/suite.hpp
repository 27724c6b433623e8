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

// "standard": loop (EuRoC-like lens distortion), figure8 (exposure changes), blackout
// (a blank transit), sweep (no revisit); all 752x480 at 20 fps with sensor noise.
std::vector<SuiteEntry> suite(const std::string& name);

}  // namespace hiveslam::synth
