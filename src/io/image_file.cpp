#include "io/image_file.hpp"

#include <cstring>
#include <optional>
#include <stdexcept>
#include <fstream>
#include <algorithm>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <vector>

#include "common/error.hpp"
#include "io/png_gray_decoder.hpp"

namespace hiveslam::io {

namespace {

bool isPng(const std::vector<uchar>& b) {
  static const uchar sig[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
  return b.size() >= 8 && std::memcmp(b.data(), sig, 8) == 0;
}
bool isJpeg(const std::vector<uchar>& b) { return b.size() >= 3 && b[0] == 0xff && b[1] == 0xd8; }

bool pngComplete(const std::vector<uchar>& b) {
  return b.size() >= 20 && std::memcmp(b.data() + b.size() - 8, "IEND", 4) == 0;
}
bool jpegComplete(const std::vector<uchar>& b) {
  // The end-of-image marker, allowing a little padding some encoders add after it.
  const size_t from = b.size() > 64 ? b.size() - 64 : 1;
  for (size_t i = b.size() - 1; i >= from; --i)
    if (b[i - 1] == 0xff && b[i] == 0xd9) return true;
  return false;
}

}  // namespace

cv::Mat readGrayImage(const std::filesystem::path& path) {
  // A list entry with an empty name is the image folder itself, which ifstream opens and whose
  // size reads as 2^63 (found by fuzz/dataset_fuzzer.cpp).
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec)) throw InputError("not an image file: " + path.string());
  std::ifstream in(path, std::ios::binary | std::ios::ate);
  if (!in) throw InputError("cannot open image " + path.string());
  // One read of the whole file (a character-wise copy showed up in the tracking profile).
  std::vector<uchar> bytes(static_cast<size_t>(std::max<std::streamoff>(in.tellg(), 0)));
  in.seekg(0);
  if (!in.read(reinterpret_cast<char*>(bytes.data()), static_cast<std::streamsize>(bytes.size())))
    throw InputError("cannot read image " + path.string());
  if (bytes.empty()) throw InputError("image file is empty: " + path.string());
  if ((isPng(bytes) && !pngComplete(bytes)) || (isJpeg(bytes) && !jpegComplete(bytes)))
    throw InputError("image file is truncated: " + path.string());
  if (isPng(bytes)) {
    try {
      if (std::optional<cv::Mat> gray = decodeGrayPng(bytes.data(), bytes.size())) return *gray;
    } catch (const std::runtime_error& e) {
      throw InputError("cannot decode image " + path.string() + ": " + e.what());
    }
  }
  cv::Mat image;
  try {
    image = cv::imdecode(bytes, cv::IMREAD_UNCHANGED);
  } catch (const cv::Exception&) {
    image.release();
  }
  if (image.empty()) throw InputError("cannot decode image " + path.string());
  if (image.depth() == CV_16U) image.convertTo(image, CV_8U, 1.0 / 256.0);
  if (image.channels() == 3) cv::cvtColor(image, image, cv::COLOR_BGR2GRAY);
  if (image.channels() == 4) cv::cvtColor(image, image, cv::COLOR_BGRA2GRAY);
  return image;
}

}  // namespace hiveslam::io
