#pragma once
// Little-endian byte writing and bounds-checked reading for message bodies. A malformed body
// throws WireError (the message is dropped), never reads past the end.
#include <cstdint>
#include <cstring>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <vector>

namespace hiveslam::distribution {

struct WireError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

class ByteWriter {
 public:
  template <typename T>
  void put(T v) {
    static_assert(std::is_trivially_copyable_v<T>);
    const auto* p = reinterpret_cast<const uint8_t*>(&v);
    out_.insert(out_.end(), p, p + sizeof(T));
  }
  void bytes(const void* p, size_t n) {
    const auto* b = static_cast<const uint8_t*>(p);
    out_.insert(out_.end(), b, b + n);
  }
  // LEB128: ids written as differences from the previous one take one or two bytes.
  void varint(uint64_t v) {
    while (v >= 0x80) {
      out_.push_back(static_cast<uint8_t>(v | 0x80));
      v >>= 7;
    }
    out_.push_back(static_cast<uint8_t>(v));
  }
  void delta(uint64_t v, uint64_t& previous) {
    const auto d = static_cast<int64_t>(v - previous);
    varint((static_cast<uint64_t>(d) << 1) ^ static_cast<uint64_t>(d >> 63));  // zigzag
    previous = v;
  }
  std::vector<uint8_t>& data() { return out_; }

 private:
  std::vector<uint8_t> out_;
};

class ByteReader {
 public:
  ByteReader(const uint8_t* data, size_t size) : p_(data), end_(data + size) {}
  template <typename T>
  T get() {
    T v;
    need(sizeof(T));
    std::memcpy(&v, p_, sizeof(T));
    p_ += sizeof(T);
    return v;
  }
  void bytes(void* out, size_t n) {
    need(n);
    std::memcpy(out, p_, n);
    p_ += n;
  }
  uint64_t varint() {
    uint64_t v = 0;
    for (int shift = 0; shift < 64; shift += 7) {
      const auto b = get<uint8_t>();
      v |= static_cast<uint64_t>(b & 0x7f) << shift;
      if (!(b & 0x80)) return v;
    }
    throw WireError("bad varint");
  }
  uint64_t delta(uint64_t& previous) {
    const uint64_t z = varint();
    const auto d = static_cast<int64_t>((z >> 1) ^ (~(z & 1) + 1));
    previous += static_cast<uint64_t>(d);
    return previous;
  }
  // A count followed by items of at least `item_bytes` each: checked against what is left.
  uint32_t count(size_t item_bytes) {
    const auto n = get<uint32_t>();
    if (item_bytes && n > static_cast<size_t>(end_ - p_) / item_bytes) throw WireError("count past the end of the message");
    return n;
  }
  bool done() const { return p_ == end_; }

 private:
  void need(size_t n) const {
    if (static_cast<size_t>(end_ - p_) < n) throw WireError("message truncated");
  }
  const uint8_t* p_;
  const uint8_t* end_;
};

}  // namespace hiveslam::distribution
