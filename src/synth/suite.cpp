#include "synth/suite.hpp"

#include "common/error.hpp"

namespace hiveslam::synth {

std::vector<SuiteEntry> suite(const std::string& name) {
  if (name != "standard") throw InputError("unknown suite '" + name + "' (standard)");
  auto make = [](const std::string& trajectory, uint64_t seed, int frames) {
    SequenceOptions o;
    o.trajectory = trajectory;
    o.seed = seed;
    o.frames = frames;
    return o;
  };
  std::vector<SuiteEntry> entries{
      {"figure8", make("figure8", 2, 1000)},
      {"blackout", make("blackout", 3, 1000)},
      {"sweep", make("sweep", 4, 800)},
      {"bigloop", make("bigloop", 5, 1000)},
  };
  entries[0].options.exposure_changes = true;
  entries[2].options.distortion = true;
  return entries;
}

}  // namespace hiveslam::synth
