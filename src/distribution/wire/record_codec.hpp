#pragma once
// Message bodies: records encoded little-endian (poses in double, point positions and image
// coordinates in float: sub-micrometre at room scale), then compressed with zstd. Decoding
// checks every count and index and throws WireError on a malformed body.
#include <cstdint>
#include <vector>

#include "core/optim/remeasurements.hpp"
#include "distribution/wire/records.hpp"

namespace hiveslam::distribution {

// Remeasured: observations TR measured again at the end of a run (core/optim/remeasurements.hpp),
// TR -> LM -> LC ahead of the end-of-sequence packet, for the final global BA.
enum class PacketKind : uint8_t { Keyframe = 1, Map = 2, Control = 3, Remeasured = 4 };
// Control packets (the target field): sent in order with the keyframes or maps of their topic.
enum class Control : uint8_t {
  EndOfSequence = 1,  // TR -> LM -> LC: no keyframe after this one
  Done = 2,           // LC -> LM, then LM -> all: everything is sent; LM's last snapshot precedes it
  // A node holds keyframes of a map it never got (the packet that started the map was lost):
  // the node that sends it keyframes answers with a snapshot of the map (the packet's `map`).
  SendMap = 3,        // LC -> LM on LC's map topic, LM -> TR on LM's
  // TR -> every peer: its link is too slow to offload to them; they leave, and TR runs alone.
  Release = 4,
};
// Raised with every change of the encoding, so that a node of another build drops what it
// cannot read with a warning instead of misreading it. 2: map records carry `update`.
// 3: re-measured observations name their point and its anchor.
constexpr uint16_t kWireVersion = 3;

std::vector<uint8_t> encode(const KeyFrameMessage& m);
std::vector<uint8_t> encode(const MapRecord& m);
// Shifts in steps of 1/256 pixel (a shift past 127 px is left out: no alignment moves that far),
// each with its point's id and anchor (keyframe back from this one, keypoint) as varints.
std::vector<uint8_t> encode(const core::Remeasurements& m);
KeyFrameMessage decodeKeyframe(const std::vector<uint8_t>& raw);
MapRecord decodeMap(const std::vector<uint8_t>& raw);
core::Remeasurements decodeRemeasurements(const std::vector<uint8_t>& raw);

std::vector<uint8_t> compress(const std::vector<uint8_t>& raw);
// raw_size bounds the output (from the packet header, checked against a 256 MB ceiling).
std::vector<uint8_t> decompress(const std::vector<uint8_t>& packed, uint32_t raw_size);

}  // namespace hiveslam::distribution
