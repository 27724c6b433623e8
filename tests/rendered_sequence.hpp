#pragma once
// A rendered sequence shared by the test processes of one build. ctest runs every test in a
// process of its own, so a sequence a test file made "once" was made again for each of its
// tests: the 240-frame loop took 7 s of this 2-core machine per node-process test, the 900-frame
// loop of the partition tests 25 s, three times. The first process to ask renders it, under a
// lock, into a folder named after the sequence and the renderer's library as built (a rebuilt
// renderer may render differently, and drops the older folders of that name); the others, of
// any test binary, read it. Callers must not write into it.
#include <fcntl.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>

#include <filesystem>
#include <map>
#include <stdexcept>
#include <string>

#include "synth/sequence.hpp"

namespace hiveslam::testing {

inline std::filesystem::path renderedSequence(const synth::SequenceOptions& options, const std::string& name) {
  namespace fs = std::filesystem;
  const fs::path root = HIVESLAM_TEST_SEQUENCES;
  struct stat renderer {};
  if (::stat(HIVESLAM_SYNTH_LIBRARY, &renderer) != 0) throw std::runtime_error("cannot stat " HIVESLAM_SYNTH_LIBRARY);
  const fs::path dir = root / (name + "-" + std::to_string(renderer.st_mtim.tv_sec) + "." +
                               std::to_string(renderer.st_mtim.tv_nsec) + "-" + std::to_string(renderer.st_size));
  fs::create_directories(root);
  const int lock = ::open((root / (name + ".lock")).c_str(), O_CREAT | O_RDWR | O_CLOEXEC, 0644);
  if (lock < 0 || ::flock(lock, LOCK_EX) != 0) throw std::runtime_error("cannot lock " + (root / name).string());
  if (!fs::exists(dir)) {
    for (const auto& entry : fs::directory_iterator(root))
      if (entry.path().filename().string().rfind(name + "-", 0) == 0) fs::remove_all(entry.path());
    // Rendered aside and renamed when whole: a folder under the final name is complete.
    const fs::path partial = root / (name + ".partial");
    fs::remove_all(partial);
    synth::writeSequence(options, partial, nullptr);
    fs::rename(partial, dir);
  }
  ::close(lock);  // releases the lock
  return dir;
}

// The process tests' loop (seed 5) of this many frames, rendered as above.
inline const std::filesystem::path& renderedLoop(int frames) {
  static std::map<int, std::filesystem::path> made;
  if (!made.count(frames)) {
    synth::SequenceOptions o;
    o.trajectory = "loop";
    o.frames = frames;
    o.seed = 5;
    made[frames] = renderedSequence(o, "loop" + std::to_string(frames) + "_seed5");
  }
  return made[frames];
}

}  // namespace hiveslam::testing
