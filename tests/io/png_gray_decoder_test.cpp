// The libdeflate PNG path against OpenCV's (libpng) decoder, on files written here with every
// row filter, several IDAT chunks, and on corrupt ones.
#include <gtest/gtest.h>
#include <libdeflate.h>

#include <cstdlib>
#include <opencv2/imgcodecs.hpp>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

#include "io/png_gray_decoder.hpp"

using hiveslam::io::decodeGrayPng;

namespace {

void put32(std::vector<uint8_t>& out, uint32_t v) {
  for (int s = 24; s >= 0; s -= 8) out.push_back(static_cast<uint8_t>(v >> s));
}

void chunk(std::vector<uint8_t>& out, const char* type, const std::vector<uint8_t>& body) {
  put32(out, static_cast<uint32_t>(body.size()));
  std::vector<uint8_t> typed(type, type + 4);
  typed.insert(typed.end(), body.begin(), body.end());
  out.insert(out.end(), typed.begin(), typed.end());
  put32(out, libdeflate_crc32(0, typed.data(), typed.size()));
}

int predictor(int filter, int a, int b, int c) {
  switch (filter) {
    case 1: return a;
    case 2: return b;
    case 3: return (a + b) >> 1;
    case 4: {
      const int pa = std::abs(b - c), pb = std::abs(a - c), pc = std::abs(a + b - 2 * c);
      return pa <= pb && pa <= pc ? a : (pb <= pc ? b : c);
    }
    default: return 0;
  }
}

struct PngOptions {
  int color_type = 0;  // 0 gray, 2 RGB
  int idat_chunks = 3;
  int bad_filter_row = -1;  // a row given filter type 5
};

// Row r uses filter r % 5, so every filter follows every other one.
std::vector<uint8_t> encode(const cv::Mat& gray, const PngOptions& o = {}) {
  const int channels = o.color_type == 2 ? 3 : 1;
  const int w = gray.cols * channels;
  std::vector<uint8_t> raw;
  for (int r = 0; r < gray.rows; ++r) {
    const int filter = r == o.bad_filter_row ? 5 : r % 5;
    raw.push_back(static_cast<uint8_t>(filter));
    for (int x = 0; x < w; ++x) {
      auto px = [&](int rr, int xx) { return rr < 0 || xx < 0 ? 0 : int{gray.at<uint8_t>(rr, xx / channels)}; };
      const int a = px(r, x - channels), b = px(r - 1, x), c = px(r - 1, x - channels);
      raw.push_back(static_cast<uint8_t>(px(r, x) - predictor(filter % 5, a, b, c)));
    }
  }
  libdeflate_compressor* comp = libdeflate_alloc_compressor(6);
  std::vector<uint8_t> z(libdeflate_zlib_compress_bound(comp, raw.size()));
  z.resize(libdeflate_zlib_compress(comp, raw.data(), raw.size(), z.data(), z.size()));
  libdeflate_free_compressor(comp);

  std::vector<uint8_t> png = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
  std::vector<uint8_t> ihdr;
  put32(ihdr, static_cast<uint32_t>(gray.cols));
  put32(ihdr, static_cast<uint32_t>(gray.rows));
  ihdr.insert(ihdr.end(), {8, static_cast<uint8_t>(o.color_type), 0, 0, 0});
  chunk(png, "IHDR", ihdr);
  chunk(png, "tEXt", {'h', 'i', 0, 'x'});  // an ancillary chunk to skip
  const size_t part = z.size() / static_cast<size_t>(o.idat_chunks) + 1;
  for (size_t at = 0; at < z.size(); at += part)
    chunk(png, "IDAT", std::vector<uint8_t>(z.begin() + static_cast<long>(at),
                                            z.begin() + static_cast<long>(std::min(z.size(), at + part))));
  chunk(png, "IEND", {});
  return png;
}

cv::Mat randomImage(int rows, int cols, unsigned seed) {
  cv::Mat m(rows, cols, CV_8UC1);
  std::mt19937 rng(seed);
  for (int r = 0; r < rows; ++r)
    for (int c = 0; c < cols; ++c) m.at<uint8_t>(r, c) = static_cast<uint8_t>(rng());
  cv::Mat smooth;
  cv::Mat(m * 0.5 + 60).copyTo(smooth);
  return smooth;
}

bool same(const cv::Mat& a, const cv::Mat& b) {
  return a.size() == b.size() && a.type() == b.type() && cv::countNonZero(a != b) == 0;
}

}  // namespace

TEST(PngGrayDecoder, AgreesWithLibpngOnEveryFilterAndChunking) {
  for (int chunks : {1, 3, 17}) {
    const cv::Mat image = randomImage(37, 53, static_cast<unsigned>(chunks));
    PngOptions o;
    o.idat_chunks = chunks;
    const std::vector<uint8_t> png = encode(image, o);
    const cv::Mat reference = cv::imdecode(png, cv::IMREAD_UNCHANGED);
    ASSERT_TRUE(same(reference, image)) << "the test's encoder is wrong";
    const auto ours = decodeGrayPng(png.data(), png.size());
    ASSERT_TRUE(ours.has_value());
    EXPECT_TRUE(same(*ours, reference)) << chunks << " IDAT chunks";
  }
}

TEST(PngGrayDecoder, AgreesWithLibpngOnOpenCvsOwnFiles) {
  const cv::Mat image = randomImage(480, 752, 7);
  for (int level : {0, 1, 9}) {
    std::vector<uint8_t> png;
    cv::imencode(".png", image, png, {cv::IMWRITE_PNG_COMPRESSION, level});
    const auto ours = decodeGrayPng(png.data(), png.size());
    ASSERT_TRUE(ours.has_value());
    EXPECT_TRUE(same(*ours, image)) << "compression " << level;
  }
}

TEST(PngGrayDecoder, OtherLayoutsAreLeftToOpenCv) {
  const cv::Mat image = randomImage(8, 8, 1);
  PngOptions rgb;
  rgb.color_type = 2;
  const std::vector<uint8_t> png = encode(image, rgb);
  EXPECT_FALSE(decodeGrayPng(png.data(), png.size()).has_value());
  const std::string jpeg = "\xff\xd8\xff\xe0 not a png";
  EXPECT_FALSE(decodeGrayPng(reinterpret_cast<const uint8_t*>(jpeg.data()), jpeg.size()).has_value());
}

TEST(PngGrayDecoder, CorruptFilesThrowInsteadOfReturningHalfAnImage) {
  const cv::Mat image = randomImage(20, 30, 3);
  PngOptions bad_filter;
  bad_filter.bad_filter_row = 7;
  std::vector<uint8_t> png = encode(image, bad_filter);
  EXPECT_THROW(decodeGrayPng(png.data(), png.size()), std::runtime_error);

  png = encode(image);
  std::vector<uint8_t> flipped = png;
  flipped[flipped.size() / 2] ^= 0x5a;  // inside the deflate stream: adler32 or structure breaks
  EXPECT_THROW(decodeGrayPng(flipped.data(), flipped.size()), std::runtime_error);

  std::vector<uint8_t> cut(png.begin(), png.begin() + static_cast<long>(png.size() / 2));
  EXPECT_THROW(decodeGrayPng(cut.data(), cut.size()), std::runtime_error);

  std::vector<uint8_t> long_chunk = png;
  long_chunk[33] = 0x7f;  // the tEXt chunk claims more bytes than the file has
  EXPECT_THROW(decodeGrayPng(long_chunk.data(), long_chunk.size()), std::runtime_error);
}
