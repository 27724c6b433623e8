// hiveslam vocab train IMAGES... --out FILE: trains the bag-of-words vocabulary on the ORB
// features of images (files or folders, searched recursively); hiveslam vocab info FILE.
#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "apps/commands.hpp"
#include "apps/progress.hpp"
#include "common/error.hpp"
#include "core/features/orb_extractor.hpp"
#include "core/place/vocabulary.hpp"

namespace hiveslam::apps {

namespace {

bool isImage(const std::filesystem::path& p) {
  std::string ext = p.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return ext == ".png" || ext == ".jpg" || ext == ".jpeg" || ext == ".bmp" || ext == ".pgm" || ext == ".tif" ||
         ext == ".tiff";
}

std::vector<std::filesystem::path> collectImages(const std::vector<std::string>& inputs, int every) {
  std::vector<std::filesystem::path> out;
  for (const auto& in : inputs) {
    const std::filesystem::path p(in);
    if (std::filesystem::is_directory(p)) {
      std::vector<std::filesystem::path> found;
      for (const auto& e : std::filesystem::recursive_directory_iterator(p))
        if (e.is_regular_file() && isImage(e.path())) found.push_back(e.path());
      std::sort(found.begin(), found.end());
      for (size_t i = 0; i < found.size(); i += static_cast<size_t>(every)) out.push_back(found[i]);
    } else if (std::filesystem::is_regular_file(p)) {
      out.push_back(p);
    } else {
      throw InputError("no such image or folder: " + in);
    }
  }
  return out;
}

}  // namespace

void addVocabCommand(CLI::App& app) {
  auto* cmd = app.add_subcommand("vocab", "Train or inspect a bag-of-words vocabulary");
  cmd->footer("Example:\n  hiveslam vocab info data/vocabulary/orb_k10_l4.bin");
  cmd->require_subcommand(1);
  auto* train = cmd->add_subcommand("train", "Train a vocabulary on the ORB features of images");
  train->footer("Example:\n  hiveslam vocab train /usr/share/doc/opencv-doc/examples/data seq/figure8 --every 3 --out vocab.bin");
  auto inputs = std::make_shared<std::vector<std::string>>();
  auto out = std::make_shared<std::string>();
  auto every = std::make_shared<int>(1);
  auto options = std::make_shared<place::VocabularyOptions>();
  auto features = std::make_shared<int>(1000);
  train->add_option("IMAGES", *inputs, "Image files or folders (searched recursively)")->required();
  train->add_option("--out", *out, "Vocabulary file to write")->required();
  train->add_option("--every", *every, "Take every N-th image of a folder")->check(CLI::PositiveNumber);
  train->add_option("--branching", options->branching, "Children per node (k)")->check(CLI::Range(2, 64));
  train->add_option("--depth", options->depth, "Levels (L)")->check(CLI::Range(1, 8));
  train->add_option("--features", *features, "ORB features per image")->check(CLI::PositiveNumber);
  train->callback([=]() {
    const auto files = collectImages(*inputs, *every);
    if (files.empty()) throw InputError("no images found");
    features::OrbOptions orb_options;
    orb_options.features = *features;
    const features::OrbExtractor orb(orb_options);
    std::vector<cv::Mat> descriptors;
    Progress progress("extracting");
    size_t total = 0;
    for (size_t i = 0; i < files.size(); ++i) {
      cv::Mat img = cv::imread(files[i].string(), cv::IMREAD_GRAYSCALE);
      if (img.empty()) throw InputError("cannot decode image " + files[i].string());
      std::vector<cv::KeyPoint> kps;
      cv::Mat d;
      orb.extract(img, kps, d);
      total += static_cast<size_t>(d.rows);
      descriptors.push_back(d);
      progress.update(static_cast<int>(i + 1), static_cast<int>(files.size()));
    }
    const auto t0 = std::chrono::steady_clock::now();
    const auto voc = place::Vocabulary::train(descriptors, *options);
    const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    voc.save(*out);
    fmt::print("{} images, {} descriptors -> {} words (k={}, L={}) in {:.1f} s: {}\n", files.size(), total,
               voc.words(), voc.branching(), voc.depth(), s, *out);
  });
  auto* info = cmd->add_subcommand("info", "Describe a vocabulary file");
  info->footer("Example:\n  hiveslam vocab info data/vocabulary/orb_k10_l4.bin");
  auto file = std::make_shared<std::string>();
  info->add_option("FILE", *file, "Vocabulary file")->required();
  info->callback([=]() {
    const auto t0 = std::chrono::steady_clock::now();
    const auto voc = place::Vocabulary::load(*file);
    const double ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
    fmt::print("{}: {} words, k={}, L={}, loaded in {:.0f} ms\n", *file, voc.words(), voc.branching(), voc.depth(), ms);
  });
}

}  // namespace hiveslam::apps
