// libFuzzer target: the wire decoders (keyframe, map and re-measurement records, and the
// zstd layer under them). The first byte picks the decoder; the rest is its input. A decoder
// may accept the bytes or throw WireError (the message is dropped); anything else (another
// exception, a crash, a sanitizer report) is a finding.
#include <cstdint>
#include <cstring>
#include <vector>

#include "distribution/wire/byte_codec.hpp"
#include "distribution/wire/record_codec.hpp"

using namespace hiveslam::distribution;

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  if (size < 1) return 0;
  const std::vector<uint8_t> body(data + 1, data + size);
  try {
    switch (data[0] % 4) {
      case 0:
        decodeKeyframe(body);
        break;
      case 1:
        decodeMap(body);
        break;
      case 2:
        decodeRemeasurements(body);
        break;
      default: {  // a packet's compressed body, after the raw size its header states
        if (body.size() < 4) return 0;
        uint32_t raw_size = 0;
        std::memcpy(&raw_size, body.data(), 4);
        const std::vector<uint8_t> packed(body.begin() + 4, body.end());
        decodeKeyframe(decompress(packed, raw_size));
      }
    }
  } catch (const WireError&) {
  }
  return 0;
}
