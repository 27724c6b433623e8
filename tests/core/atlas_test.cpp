// Saving and loading an atlas, and localization against a loaded one.
#include <gtest/gtest.h>

#include <algorithm>
#include <fstream>
#include <iterator>
#include <limits>

#include "common/error.hpp"
#include "core/camera/pinhole_radtan.hpp"
#include "core/features/orb_extractor.hpp"
#include "core/system/slam_system.hpp"
#include "io/atlas_file.hpp"
#include "synth/sequence.hpp"
#include "temp_dir.hpp"

namespace hiveslam::core {
namespace {

struct Rendered {
  synth::SequenceModel model;
  std::vector<cv::Mat> images;
  std::shared_ptr<camera::PinholeRadTan> camera;
};

const Rendered& sweep() {
  static const Rendered r = [] {
    synth::SequenceOptions o;
    o.trajectory = "sweep";
    o.frames = 600;
    o.seed = 4;
    Rendered out{synth::buildSequence(o), {}, nullptr};
    const synth::RayTable rays(out.model.lens);
    for (int f = 100; f < 240; ++f) out.images.push_back(out.model.renderImage(f, rays));
    const auto& l = out.model.lens;
    out.camera = std::make_shared<camera::PinholeRadTan>(l.width, l.height, l.fx, l.fy, l.cx, l.cy);
    return out;
  }();
  return r;
}

std::string bytesOf(const std::filesystem::path& p) {
  std::ifstream in(p, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

TEST(Atlas, SaveThenLoadGivesAnIdenticalMap) {
  const Rendered& r = sweep();
  SlamSystem slam(SlamSettings{}, r.camera, SlamSystem::Mode::Sequential);
  for (size_t i = 0; i < r.images.size(); ++i) slam.process(r.images[i], r.model.stamp(static_cast<int>(i) + 100));
  slam.finish();
  const auto maps = slam.liveMaps();
  ASSERT_FALSE(maps.empty());
  testing::TempDir dir;
  io::saveAtlas(dir.path() / "a.atlas", maps);
  const auto loaded = io::loadAtlas(dir.path() / "a.atlas");
  ASSERT_EQ(loaded.size(), maps.size());
  int weak = 0;
  for (size_t m = 0; m < maps.size(); ++m) {
    const Map& a = *maps[m];
    const Map& b = *loaded[m];
    EXPECT_EQ(a.id, b.id);
    ASSERT_EQ(a.keyframes.size(), b.keyframes.size());
    ASSERT_EQ(a.points.size(), b.points.size());
    ASSERT_TRUE(a.origin && b.origin);
    EXPECT_EQ(a.origin->id, b.origin->id);
    for (const auto& [id, ka] : a.keyframes) {
      const KeyFrame& kb = *b.keyframes.at(id);
      EXPECT_LT((ka->T_cw.matrix() - kb.T_cw.matrix()).norm(), 1e-12);
      EXPECT_EQ(ka->frame.timestamp, kb.frame.timestamp);
      ASSERT_EQ(ka->frame.size(), kb.frame.size());
      EXPECT_EQ(cv::norm(ka->frame.descriptors, kb.frame.descriptors, cv::NORM_HAMMING), 0);
      for (size_t i = 0; i < ka->frame.size(); ++i) {
        EXPECT_EQ(ka->frame.points[i], kb.frame.points[i]);
        EXPECT_EQ(ka->frame.keypoints[i].octave, kb.frame.keypoints[i].octave);
        EXPECT_EQ(features::isWeakCorner(ka->frame.keypoints[i]), features::isWeakCorner(kb.frame.keypoints[i]));
        weak += features::isWeakCorner(ka->frame.keypoints[i]);
        EXPECT_EQ(ka->points[i] ? ka->points[i]->id : kNoId, kb.points[i] ? kb.points[i]->id : kNoId);
      }
      EXPECT_EQ(ka->parent ? ka->parent->id : kNoId, kb.parent ? kb.parent->id : kNoId);
      ASSERT_EQ(ka->covisibility.size(), kb.covisibility.size()) << id;
      for (const auto& [n, w] : ka->covisibility) {
        const KeyFrame* nb = b.keyframes.at(n->id).get();
        ASSERT_TRUE(kb.covisibility.count(const_cast<KeyFrame*>(nb)));
        EXPECT_EQ(w, kb.covisibility.at(const_cast<KeyFrame*>(nb)));
      }
    }
    for (const auto& [id, pa] : a.points) {
      const MapPoint& pb = *b.points.at(id);
      EXPECT_EQ(pa->position, pb.position);
      EXPECT_EQ(pa->normal, pb.normal);
      EXPECT_EQ(pa->observations.size(), pb.observations.size());
      EXPECT_EQ(cv::norm(pa->descriptor, pb.descriptor, cv::NORM_HAMMING), 0);
    }
  }
  EXPECT_GT(weak, 0) << "the sweep's keyframes hold weak corners, whose flag must survive";
  // Saving the loaded atlas again writes the same bytes.
  io::saveAtlas(dir.path() / "b.atlas", loaded);
  const std::string first = bytesOf(dir.path() / "a.atlas"), second = bytesOf(dir.path() / "b.atlas");
  ASSERT_EQ(first.size(), second.size());
  EXPECT_TRUE(first == second) << "first differing byte at " << std::mismatch(first.begin(), first.end(), second.begin()).first - first.begin();

  // Localization against it: the frames are tracked again, and nothing is added to the map.
  SlamSystem loc(SlamSettings{}, r.camera, SlamSystem::Mode::Sequential);
  loc.loadAtlas(loaded, true);
  const size_t kfs = loaded.front()->keyframes.size(), pts = loaded.front()->points.size();
  int tracked = 0;
  for (size_t i = 0; i < r.images.size(); ++i)
    tracked += loc.process(r.images[i], r.model.stamp(static_cast<int>(i) + 100)).tracked;
  loc.finish();
  EXPECT_GE(tracked, static_cast<int>(0.9 * r.images.size()));
  EXPECT_EQ(loaded.front()->keyframes.size(), kfs);
  EXPECT_EQ(loaded.front()->points.size(), pts);
  EXPECT_EQ(loc.liveMaps().size(), loaded.size());
}

TEST(Atlas, RejectsMissingTruncatedAndForeignFiles) {
  testing::TempDir dir;
  EXPECT_THROW(io::loadAtlas(dir.path() / "none.atlas"), InputError);
  std::ofstream(dir.path() / "foreign.atlas") << "something else entirely";
  EXPECT_THROW(io::loadAtlas(dir.path() / "foreign.atlas"), InputError);
  const Rendered& r = sweep();
  SlamSystem slam(SlamSettings{}, r.camera, SlamSystem::Mode::Sequential);
  for (size_t i = 0; i < 60; ++i) slam.process(r.images[i], r.model.stamp(static_cast<int>(i) + 100));
  slam.finish();
  io::saveAtlas(dir.path() / "a.atlas", slam.liveMaps());
  const std::string bytes = bytesOf(dir.path() / "a.atlas");
  ASSERT_GT(bytes.size(), 1000u);
  for (size_t cut : {bytes.size() / 3, bytes.size() - 7}) {
    std::ofstream(dir.path() / "cut.atlas", std::ios::binary) << bytes.substr(0, cut);
    EXPECT_THROW(io::loadAtlas(dir.path() / "cut.atlas"), InputError) << cut;
  }
}

// What fuzz/dataset_fuzzer.cpp found the loader taking: a point at NaN (it would spread through
// every BA) and a spanning tree with a cycle (loop correction walks each keyframe's parents).
TEST(Atlas, RejectsNumbersThatAreNotAndASpanningTreeWithACycle) {
  const Rendered& r = sweep();
  SlamSystem slam(SlamSettings{}, r.camera, SlamSystem::Mode::Sequential);
  for (size_t i = 0; i < 60; ++i) slam.process(r.images[i], r.model.stamp(static_cast<int>(i) + 100));
  slam.finish();
  const auto map = slam.largestMap();
  ASSERT_GE(map->keyframes.size(), 3u);
  testing::TempDir dir;
  auto errorOf = [&](const char* name) -> std::string {
    io::saveAtlas(dir.path() / name, {map});
    try {
      io::loadAtlas(dir.path() / name);
    } catch (const InputError& e) {
      return e.what();
    }
    return "loaded";
  };
  MapPoint& point = *map->points.begin()->second;
  const Eigen::Vector3d position = point.position;
  point.position.x() = std::numeric_limits<double>::quiet_NaN();
  EXPECT_NE(errorOf("nan.atlas").find("point position that is not a number"), std::string::npos);
  point.position = position;
  // Two keyframes each other's parent.
  auto it = map->keyframes.begin();
  KeyFrame& a = *(it++)->second;
  KeyFrame& b = *it->second;
  a.parent = &b;
  b.parent = &a;
  EXPECT_NE(errorOf("cycle.atlas").find("spanning tree cycle"), std::string::npos);
}

}  // namespace
}  // namespace hiveslam::core
