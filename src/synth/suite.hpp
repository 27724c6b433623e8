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
std::vector<SuiteEntry> suite(const std::string& name);

}  // namespace hiveslam::synth
