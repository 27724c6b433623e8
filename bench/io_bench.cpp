// Image decoding, the tracking thread's second largest cost after FAST: one rendered 752x480
// frame written the way `hiveslam synth` writes it, decoded by OpenCV (libpng + zlib) and by
// the libdeflate path readGrayImage takes for 8-bit grayscale PNGs.
#include <benchmark/benchmark.h>

#include <opencv2/imgcodecs.hpp>
#include <vector>

#include "io/png_gray_decoder.hpp"
#include "synth/sequence.hpp"

namespace {

const std::vector<uchar>& png() {
  static const std::vector<uchar> bytes = [] {
    hiveslam::synth::SequenceOptions o;
    const auto model = hiveslam::synth::buildSequence(o);
    std::vector<uchar> out;
    cv::imencode(".png", model.renderImage(200, hiveslam::synth::RayTable(model.lens)), out);
    return out;
  }();
  return bytes;
}

void DecodePngOpenCv(benchmark::State& state) {
  for (auto _ : state) benchmark::DoNotOptimize(cv::imdecode(png(), cv::IMREAD_UNCHANGED));
}
BENCHMARK(DecodePngOpenCv)->Unit(benchmark::kMillisecond);

void DecodePngLibdeflate(benchmark::State& state) {
  for (auto _ : state) benchmark::DoNotOptimize(hiveslam::io::decodeGrayPng(png().data(), png().size()));
}
BENCHMARK(DecodePngLibdeflate)->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
