#include "synth/suite.hpp"

#include <fmt/format.h>

#include <filesystem>

#include "common/error.hpp"

namespace hiveslam::synth {

const char* const kDebianPhotos = "/usr/share/doc/opencv-doc/examples/data";

std::vector<SuiteEntry> suite(const std::string& name, const std::string& textures) {
  if (name == "realistic") {
    std::vector<SuiteEntry> entries;
    const std::string photos = !textures.empty() ? textures : std::filesystem::is_directory(kDebianPhotos) ? kDebianPhotos : "";
    int k = 0;
    for (int frames : {1000, 1050, 1100, 1200}) {
      SequenceOptions o;
      o.trajectory = "handheld";
      o.seed = 201 + static_cast<uint64_t>(k);
      o.frames = frames;
      o.width = 640;
      o.height = 480;
      o.fps = 30;
      o.realistic = true;
      o.textures = photos;
      entries.push_back({fmt::format("handheld{}", ++k), o});
    }
    return entries;
  }
  if (name != "standard") throw InputError("unknown suite '" + name + "' (standard, realistic)");
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
