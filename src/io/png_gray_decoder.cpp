#include "io/png_gray_decoder.hpp"

#include <libdeflate.h>

#include <cstdlib>
#include <cstring>
#include <memory>
#include <stdexcept>
#include <vector>

namespace hiveslam::io {

namespace {

uint32_t bigEndian32(const uint8_t* p) {
  return (uint32_t{p[0]} << 24) | (uint32_t{p[1]} << 16) | (uint32_t{p[2]} << 8) | uint32_t{p[3]};
}

struct DecompressorDeleter {
  void operator()(libdeflate_decompressor* d) const { libdeflate_free_decompressor(d); }
};

libdeflate_decompressor& threadDecompressor() {
  thread_local std::unique_ptr<libdeflate_decompressor, DecompressorDeleter> d(libdeflate_alloc_decompressor());
  if (!d) throw std::runtime_error("cannot allocate a deflate decompressor");
  return *d;
}

uint8_t paeth(int a, int b, int c) {
  const int pa = std::abs(b - c), pb = std::abs(a - c), pc = std::abs(a + b - 2 * c);
  if (pa <= pb && pa <= pc) return static_cast<uint8_t>(a);
  return static_cast<uint8_t>(pb <= pc ? b : c);
}

// Undoes one row's filter (PNG spec section 9, one byte per pixel). `prior` is the previous
// reconstructed row, or nullptr on the first row, where it reads as zeros.
void unfilterRow(int filter, const uint8_t* in, const uint8_t* prior, uint8_t* out, int width) {
  switch (filter) {
    case 0:
      std::memcpy(out, in, static_cast<size_t>(width));
      return;
    case 1: {
      uint8_t left = 0;
      for (int x = 0; x < width; ++x) out[x] = left = static_cast<uint8_t>(in[x] + left);
      return;
    }
    case 2:
      if (!prior) {
        std::memcpy(out, in, static_cast<size_t>(width));
      } else {
        for (int x = 0; x < width; ++x) out[x] = static_cast<uint8_t>(in[x] + prior[x]);
      }
      return;
    case 3: {
      int left = 0;
      for (int x = 0; x < width; ++x) {
        const int up = prior ? prior[x] : 0;
        out[x] = static_cast<uint8_t>(in[x] + ((left + up) >> 1));
        left = out[x];
      }
      return;
    }
    case 4: {
      int left = 0, up_left = 0;
      for (int x = 0; x < width; ++x) {
        const int up = prior ? prior[x] : 0;
        out[x] = static_cast<uint8_t>(in[x] + paeth(left, up, up_left));
        left = out[x];
        up_left = up;
      }
      return;
    }
    default:
      throw std::runtime_error("PNG row with unknown filter type " + std::to_string(filter));
  }
}

}  // namespace

std::optional<cv::Mat> decodeGrayPng(const uint8_t* data, size_t size) {
  static const uint8_t kSignature[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
  if (size < 8 + 25 || std::memcmp(data, kSignature, 8) != 0) return std::nullopt;
  // IHDR must come first: 13 bytes of width, height, depth, colour type, compression, filter,
  // interlace.
  if (bigEndian32(data + 8) != 13 || std::memcmp(data + 12, "IHDR", 4) != 0)
    throw std::runtime_error("PNG without a leading IHDR chunk");
  const uint8_t* ihdr = data + 16;
  const uint32_t width = bigEndian32(ihdr), height = bigEndian32(ihdr + 4);
  const bool gray8 = ihdr[8] == 8 && ihdr[9] == 0 && ihdr[10] == 0 && ihdr[11] == 0 && ihdr[12] == 0;
  if (!gray8) return std::nullopt;
  if (width == 0 || height == 0 || width > (1u << 16) || height > (1u << 16))
    throw std::runtime_error("PNG with an implausible size");

  // The IDAT chunks form one zlib stream; one chunk (the usual case for small encoders) is
  // inflated in place, several are joined first.
  thread_local std::vector<uint8_t> joined;
  const uint8_t* stream = nullptr;
  size_t stream_size = 0;
  int idat_chunks = 0;
  bool ended = false;
  for (size_t at = 8; at + 12 <= size;) {
    const size_t length = bigEndian32(data + at);
    if (length > size - at - 12) throw std::runtime_error("PNG chunk runs past the end of the file");
    const uint8_t* type = data + at + 4;
    const uint8_t* body = data + at + 8;
    if (std::memcmp(type, "IDAT", 4) == 0) {
      if (idat_chunks == 0) {
        stream = body;
        stream_size = length;
      } else {
        if (idat_chunks == 1) joined.assign(stream, stream + stream_size);
        joined.insert(joined.end(), body, body + length);
      }
      ++idat_chunks;
    } else if (std::memcmp(type, "IEND", 4) == 0) {
      ended = true;
      break;
    }
    at += 12 + length;
  }
  if (idat_chunks == 0 || !ended) throw std::runtime_error("PNG without image data or its end chunk");
  if (idat_chunks > 1) {
    stream = joined.data();
    stream_size = joined.size();
  }

  // Every row is a filter byte followed by `width` pixels.
  const size_t stride = size_t{width} + 1;
  thread_local std::vector<uint8_t> raw;
  raw.resize(stride * height);
  size_t inflated = 0;
  if (libdeflate_zlib_decompress(&threadDecompressor(), stream, stream_size, raw.data(), raw.size(), &inflated) !=
          LIBDEFLATE_SUCCESS ||
      inflated != raw.size())
    throw std::runtime_error("PNG image data does not inflate to its size");

  cv::Mat image(static_cast<int>(height), static_cast<int>(width), CV_8UC1);
  for (int r = 0; r < image.rows; ++r) {
    const uint8_t* row = raw.data() + stride * static_cast<size_t>(r);
    unfilterRow(row[0], row + 1, r > 0 ? image.ptr<uint8_t>(r - 1) : nullptr, image.ptr<uint8_t>(r), image.cols);
  }
  return image;
}

}  // namespace hiveslam::io
