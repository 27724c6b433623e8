// Writes the wire fuzzer's seed corpus: one valid message per decoder, in wire_fuzzer's input
// format (a byte that picks the decoder, then its input), so that mutations start from the
// shapes real packets have instead of from nothing.
//
//   wire_seeds DIR
#include <cstdio>
#include <cstring>
#include <fstream>
#include <string>

#include "distribution/wire/record_codec.hpp"
#include "distribution/wire_samples.hpp"

using namespace hiveslam;
using namespace hiveslam::distribution;

namespace {

void write(const std::string& path, uint8_t selector, const std::vector<uint8_t>& body) {
  std::ofstream out(path, std::ios::binary);
  out.put(static_cast<char>(selector));
  out.write(reinterpret_cast<const char*>(body.data()), static_cast<std::streamsize>(body.size()));
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: wire_seeds DIR\n");
    return 2;
  }
  const std::string dir = argv[1];
  KeyFrameMessage k = sampleKeyframe();
  k.companions.push_back(k.keyframe);
  k.stats.push_back({100, 5, 3});
  MapRecord m = sampleMap();
  m.batches = 2;
  m.erased_keyframes = {8};
  m.merged_maps = {6};
  const core::Remeasurements r = sampleRemeasurements();
  write(dir + "/keyframe", 0, encode(k));
  write(dir + "/map", 1, encode(m));
  write(dir + "/remeasured", 2, encode(r));
  const auto raw = encode(k);
  std::vector<uint8_t> packet(4);
  const auto size = static_cast<uint32_t>(raw.size());
  std::memcpy(packet.data(), &size, 4);
  const auto packed = compress(raw);
  packet.insert(packet.end(), packed.begin(), packed.end());
  write(dir + "/packet", 3, packet);
  return 0;
}
