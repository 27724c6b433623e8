#include <gtest/gtest.h>

#include <fstream>
#include <random>

#include "common/error.hpp"
#include "core/features/orb_extractor.hpp"
#include "core/place/vocabulary.hpp"
#include "synth/renderer.hpp"
#include "synth/sequence.hpp"
#include "temp_dir.hpp"

namespace hiveslam::place {
namespace {

const std::string kShipped = std::string(HIVESLAM_SOURCE_DIR) + "/data/vocabulary/orb_k10_l4.bin";

// The rendered loop passes its start again at about 41.5 s (frame 830): the shipped vocabulary
// must score that revisit above views of other parts of the room.
TEST(Vocabulary, ScoresARevisitedPlaceAboveUnrelatedOnes) {
  const Vocabulary voc = Vocabulary::load(kShipped);
  synth::SequenceOptions o;
  o.trajectory = "loop";
  const auto model = synth::buildSequence(o);
  const synth::RayTable rays(model.lens);
  const features::OrbExtractor orb;
  auto describe = [&](int frame) {
    std::vector<cv::KeyPoint> kps;
    cv::Mat d;
    orb.extract(model.renderImage(frame, rays), kps, d);
    BowVector bow;
    FeatureVector fv;
    voc.transform(d, bow, fv);
    return bow;
  };
  const BowVector start = describe(20), revisit = describe(830);
  const double same = scoreL1(start, revisit);
  for (int other : {200, 300, 400, 500, 600}) EXPECT_GT(same, 1.3 * scoreL1(start, describe(other))) << other;
}

TEST(Vocabulary, TrainSaveLoadGivesTheSameWords) {
  std::mt19937 rng(3);
  std::vector<cv::Mat> images;
  for (int img = 0; img < 6; ++img) {
    cv::Mat d(300, 32, CV_8U);
    cv::randu(d, 0, 256);
    images.push_back(d);
  }
  VocabularyOptions o;
  o.branching = 4;
  o.depth = 3;
  const Vocabulary voc = Vocabulary::train(images, o);
  EXPECT_GT(voc.words(), 30u);
  EXPECT_LE(voc.words(), 64u);
  testing::TempDir dir;
  voc.save(dir.path() / "v.bin");
  const Vocabulary back = Vocabulary::load(dir.path() / "v.bin");
  ASSERT_EQ(back.words(), voc.words());
  for (int r = 0; r < images[0].rows; ++r)
    EXPECT_EQ(back.wordOf(images[0].ptr<uint8_t>(r)), voc.wordOf(images[0].ptr<uint8_t>(r)));
  BowVector a, b;
  FeatureVector fa, fb;
  voc.transform(images[1], a, fa);
  back.transform(images[1], b, fb);
  EXPECT_EQ(a, b);
  EXPECT_EQ(fa, fb);
  EXPECT_NEAR(scoreL1(a, a), 1.0, 1e-9);
}

TEST(Vocabulary, RejectsMissingTruncatedAndForeignFiles) {
  testing::TempDir dir;
  EXPECT_THROW(Vocabulary::load(dir.path() / "none.bin"), InputError);
  std::ofstream(dir.path() / "foreign.bin") << "not a vocabulary at all";
  EXPECT_THROW(Vocabulary::load(dir.path() / "foreign.bin"), InputError);
  std::ifstream in(kShipped, std::ios::binary);
  std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  std::ofstream(dir.path() / "cut.bin", std::ios::binary) << bytes.substr(0, bytes.size() / 2);
  EXPECT_THROW(Vocabulary::load(dir.path() / "cut.bin"), InputError);
}

}  // namespace
}  // namespace hiveslam::place
