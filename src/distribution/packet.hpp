#pragma once
// Record bodies in and out of communication::Message (encoding plus compression).
#include "communication/message.hpp"
#include "distribution/wire/byte_codec.hpp"
#include "distribution/wire/record_codec.hpp"

namespace hiveslam::distribution {

template <typename Record>
communication::Message pack(const Record& record, uint16_t source, uint8_t target, Id map, uint64_t epoch) {
  communication::Message m;
  m.version = kWireVersion;
  m.source = source;
  m.kind = static_cast<uint8_t>(std::is_same_v<Record, MapRecord>              ? PacketKind::Map
                                : std::is_same_v<Record, core::Remeasurements> ? PacketKind::Remeasured
                                                                               : PacketKind::Keyframe);
  m.target = target;
  m.map = map;
  m.epoch = epoch;
  const std::vector<uint8_t> raw = encode(record);
  m.raw_size = static_cast<uint32_t>(raw.size());
  m.body = compress(raw);
  return m;
}

// A control packet: header only, the command in the target field (and the map it is about).
inline communication::Message controlPacket(uint16_t source, Control command, uint64_t map = 0) {
  communication::Message m;
  m.source = source;
  m.kind = static_cast<uint8_t>(PacketKind::Control);
  m.target = static_cast<uint8_t>(command);
  m.map = map;
  return m;
}

inline std::vector<uint8_t> unpack(const communication::Message& m, PacketKind expected) {
  if (m.version != kWireVersion) throw WireError("wire version " + std::to_string(m.version) + " not supported");
  if (m.kind != static_cast<uint8_t>(expected)) throw WireError("unexpected packet kind");
  return decompress(m.body, m.raw_size);
}

}  // namespace hiveslam::distribution
