// Writes the dataset fuzzer's binary seeds in its input format (a byte that picks the reader,
// then the file), so that mutations start from the shapes real files have: a small saved atlas
// (two maps, keyframes with keypoints, points seen by several keyframes, a spanning tree,
// covisibility and a loop edge) and PNG and JPEG images. The text seeds are written by scripts/fuzz.
//
//   dataset_seeds DIR
#include <cstdio>
#include <fstream>
#include <iterator>
#include <string>

#include <opencv2/imgcodecs.hpp>

#include "io/atlas_file.hpp"

using namespace hiveslam;

namespace {

std::shared_ptr<core::Map> sampleMap(core::Id first_id, int keyframes, int points) {
  core::Id id = first_id;
  auto map = std::make_shared<core::Map>(id++);
  std::vector<std::shared_ptr<core::KeyFrame>> kfs;
  for (int k = 0; k < keyframes; ++k) {
    core::Frame f;
    f.index = static_cast<size_t>(10 * k);
    f.timestamp = 0.5 * k;
    f.K = {50, 50, 32, 24};
    f.width = 64;
    f.height = 48;
    f.descriptors = cv::Mat(points, 32, CV_8U);
    for (int i = 0; i < points; ++i) {
      const float x = static_cast<float>(4 + (i * 7) % 56), y = static_cast<float>(4 + (i * 11) % 40);
      f.keypoints.emplace_back(x, y, 31.f, 0.f, 10.f, i % 3);
      f.points.emplace_back(x, y);
      for (int b = 0; b < 32; ++b) f.descriptors.at<uint8_t>(i, b) = static_cast<uint8_t>(i * 31 + b * 7 + k);
    }
    f.buildGrid();
    Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
    T.translation() = Eigen::Vector3d(-0.1 * k, 0, 0);
    auto kf = std::make_shared<core::KeyFrame>(id++, std::move(f), T);
    if (!kfs.empty()) {
      kf->parent = kfs.back().get();
      kfs.back()->children.insert(kf.get());
    }
    map->add(kf);
    kfs.push_back(kf);
  }
  map->origin = kfs.front().get();
  for (int i = 0; i < points; ++i) {
    auto p = std::make_shared<core::MapPoint>(id++, Eigen::Vector3d((i % 56 - 28) / 50.0, (i % 40 - 20) / 50.0, 1.0),
                                              kfs.front()->id);
    p->descriptor = kfs.front()->frame.descriptors.row(i).clone();
    for (auto& kf : kfs) core::Map::observe(*kf, i, p);
    map->add(p);
  }
  for (auto& kf : kfs) kf->updateConnections();
  kfs.back()->loop_edges.insert(kfs.front().get());
  kfs.front()->loop_edges.insert(kfs.back().get());
  return map;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: dataset_seeds DIR\n");
    return 2;
  }
  const std::string dir = argv[1];
  const std::string atlas = dir + "/atlas.tmp";
  io::saveAtlas(atlas, {sampleMap(1, 3, 20), sampleMap(1000, 2, 12)});
  std::ifstream in(atlas, std::ios::binary);
  const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  std::ofstream out(dir + "/atlas", std::ios::binary);
  out.put(0);  // dataset_fuzzer's reader 0: an atlas
  out << bytes;
  std::remove(atlas.c_str());
  // Reader 6: image files, a small grey and a colour one in PNG and JPEG.
  cv::Mat gray(24, 32, CV_8UC1), colour(24, 32, CV_8UC3);
  cv::randu(gray, 0, 255);
  cv::randu(colour, 0, 255);
  int n = 0;
  for (const cv::Mat* image : {&gray, &colour})
    for (const char* ext : {".png", ".jpg"}) {
      std::vector<uchar> bytes;
      cv::imencode(ext, *image, bytes);
      std::ofstream file(dir + "/image" + std::to_string(n++) + ext, std::ios::binary);
      file.put(6);
      file.write(reinterpret_cast<const char*>(bytes.data()), static_cast<std::streamsize>(bytes.size()));
    }
  return 0;
}
