#include "io/atlas_file.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <fstream>
#include <unordered_set>

#include "common/error.hpp"
#include "core/features/orb_extractor.hpp"

namespace hiveslam::io {

namespace {

constexpr char kMagic[8] = {'H', 'S', 'A', 'T', 'L', 'A', 'S', '\0'};
constexpr uint32_t kVersion = 1;

class Writer {
 public:
  explicit Writer(std::ofstream& out) : out_(out) {}
  template <typename T>
  void put(const T& v) {
    out_.write(reinterpret_cast<const char*>(&v), sizeof(T));
  }
  void bytes(const void* p, size_t n) { out_.write(static_cast<const char*>(p), static_cast<std::streamsize>(n)); }
  // The 3x4 matrix row by row: a load gives back the very same doubles.
  void pose(const Eigen::Isometry3d& T) {
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 4; ++c) put(T.matrix()(r, c));
  }

 private:
  std::ofstream& out_;
};

class Reader {
 public:
  Reader(std::ifstream& in, std::string file) : in_(in), file_(std::move(file)) {}
  template <typename T>
  T get() {
    T v{};
    if (!in_.read(reinterpret_cast<char*>(&v), sizeof(T))) throw InputError("truncated atlas file: " + file_);
    return v;
  }
  void bytes(void* p, size_t n) {
    if (!in_.read(static_cast<char*>(p), static_cast<std::streamsize>(n))) throw InputError("truncated atlas file: " + file_);
  }
  uint32_t count(uint32_t max, const char* what) {
    const auto n = get<uint32_t>();
    if (n > max) throw InputError("corrupt atlas file (" + std::string(what) + " count " + std::to_string(n) + "): " + file_);
    return n;
  }
  Eigen::Isometry3d pose() {
    Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 4; ++c) T.matrix()(r, c) = get<double>();
    const Eigen::Matrix3d R = T.linear();
    if (!T.matrix().allFinite() || !(R.transpose() * R).isApprox(Eigen::Matrix3d::Identity(), 1e-6))
      throw InputError("corrupt atlas pose: " + file_);
    return T;
  }
  // A number the map will compute with: a NaN or an infinity would spread through every BA.
  double finite(const char* what) {
    const double v = get<double>();
    if (!std::isfinite(v)) corrupt(std::string("a ") + what + " that is not a number");
    return v;
  }
  [[noreturn]] void corrupt(const std::string& why) const { throw InputError("corrupt atlas file (" + why + "): " + file_); }

 private:
  std::ifstream& in_;
  std::string file_;
};

template <typename T>
std::vector<T*> sortedById(const std::unordered_map<core::Id, std::shared_ptr<T>>& m) {
  std::vector<T*> v;
  for (const auto& [id, x] : m) v.push_back(x.get());
  std::sort(v.begin(), v.end(), [](T* a, T* b) { return a->id < b->id; });
  return v;
}

}  // namespace

void saveAtlas(const std::filesystem::path& file, const std::vector<std::shared_ptr<core::Map>>& maps) {
  std::ofstream out(file, std::ios::binary);
  if (!out) throw InputError("cannot write atlas " + file.string());
  Writer w(out);
  w.bytes(kMagic, sizeof(kMagic));
  w.put(kVersion);
  w.put(static_cast<uint32_t>(maps.size()));
  for (const auto& map : maps) {
    std::lock_guard lock(map->mutex);
    const auto kfs = sortedById(map->keyframes);
    const auto points = sortedById(map->points);
    w.put(map->id);
    w.put(map->origin ? map->origin->id : core::kNoId);
    w.put(static_cast<uint32_t>(kfs.size()));
    w.put(static_cast<uint32_t>(points.size()));
    for (const core::KeyFrame* kf : kfs) {
      const core::Frame& f = kf->frame;
      w.put(kf->id);
      w.put(static_cast<uint64_t>(f.index));
      w.put(f.timestamp);
      w.pose(kf->T_cw);
      w.put(kf->parent ? kf->parent->id : core::kNoId);
      w.put(static_cast<uint32_t>(kf->loop_edges.size()));
      for (const core::KeyFrame* l : kf->loop_edges) w.put(l->id);
      w.put(static_cast<uint32_t>(kf->covisibility.size()));
      for (const auto& [n, weight] : kf->covisibility) {
        w.put(n->id);
        w.put(static_cast<int32_t>(weight));
      }
      for (double x : {f.K.fx, f.K.fy, f.K.cx, f.K.cy}) w.put(x);
      w.put(static_cast<int32_t>(f.width));
      w.put(static_cast<int32_t>(f.height));
      w.put(static_cast<uint32_t>(f.keypoints.size()));
      for (size_t i = 0; i < f.keypoints.size(); ++i) {
        const cv::KeyPoint& k = f.keypoints[i];
        for (float x : {k.pt.x, k.pt.y, k.size, k.angle, k.response}) w.put(x);
        w.put(static_cast<int32_t>(k.octave | (features::isWeakCorner(k) ? 0x100 : 0)));  // weak flag above the level
        w.put(f.points[i].x());
        w.put(f.points[i].y());
        w.bytes(f.descriptors.ptr<uint8_t>(static_cast<int>(i)), 32);
      }
    }
    for (const core::MapPoint* p : points) {
      w.put(p->id);
      for (int i = 0; i < 3; ++i) w.put(p->position[i]);
      w.put(p->first_keyframe);
      w.bytes(p->descriptor.ptr<uint8_t>(), 32);
      for (int i = 0; i < 3; ++i) w.put(p->normal[i]);
      w.put(p->min_distance);
      w.put(p->max_distance);
      w.put(static_cast<int32_t>(p->visible));
      w.put(static_cast<int32_t>(p->found));
      w.put(static_cast<uint32_t>(p->observations.size()));
      for (const auto& [kf, idx] : p->observations) {
        w.put(kf->id);
        w.put(static_cast<int32_t>(idx));
      }
    }
  }
  if (!out) throw InputError("cannot write atlas " + file.string());
}

std::vector<std::shared_ptr<core::Map>> loadAtlas(const std::filesystem::path& file,
                                                  const place::Vocabulary* vocabulary) {
  std::ifstream in(file, std::ios::binary);
  if (!in) throw InputError("cannot open atlas " + file.string());
  Reader r(in, file.string());
  char magic[8];
  r.bytes(magic, 8);
  if (std::memcmp(magic, kMagic, 8) != 0) throw InputError("not a hiveslam atlas: " + file.string());
  const auto version = r.get<uint32_t>();
  if (version != kVersion)
    throw InputError("atlas version " + std::to_string(version) + " not supported (this build reads " +
                     std::to_string(kVersion) + "): " + file.string());
  std::vector<std::shared_ptr<core::Map>> maps;
  const uint32_t map_count = r.count(100000, "map");
  for (uint32_t m = 0; m < map_count; ++m) {
    auto map = std::make_shared<core::Map>(r.get<core::Id>());
    const auto origin = r.get<core::Id>();
    const uint32_t kf_count = r.count(10'000'000, "keyframe");
    const uint32_t point_count = r.count(100'000'000, "point");
    std::vector<std::pair<core::KeyFrame*, core::Id>> parents;
    std::vector<std::pair<core::KeyFrame*, std::vector<core::Id>>> loops;
    std::vector<std::pair<core::KeyFrame*, std::vector<std::pair<core::Id, int>>>> covisibility;
    for (uint32_t k = 0; k < kf_count; ++k) {
      const auto id = r.get<core::Id>();
      core::Frame f;
      f.index = r.get<uint64_t>();
      f.timestamp = r.finite("timestamp");
      const Eigen::Isometry3d T_cw = r.pose();
      const auto parent = r.get<core::Id>();
      std::vector<core::Id> loop_ids(r.count(1'000'000, "loop edge"));
      for (auto& l : loop_ids) l = r.get<core::Id>();
      std::vector<std::pair<core::Id, int>> covisible(r.count(10'000'000, "covisibility"));
      for (auto& [n, weight] : covisible) {
        n = r.get<core::Id>();
        weight = r.get<int32_t>();
      }
      f.K.fx = r.finite("focal length");
      f.K.fy = r.finite("focal length");
      f.K.cx = r.finite("principal point");
      f.K.cy = r.finite("principal point");
      if (!(f.K.fx > 0) || !(f.K.fy > 0)) r.corrupt("focal length");
      f.width = r.get<int32_t>();
      f.height = r.get<int32_t>();
      if (f.width <= 0 || f.height <= 0 || f.width > 100000 || f.height > 100000) r.corrupt("image size");
      const uint32_t n = r.count(1'000'000, "keypoint");
      f.descriptors = cv::Mat(static_cast<int>(n), 32, CV_8U);
      for (uint32_t i = 0; i < n; ++i) {
        cv::KeyPoint kp;
        kp.pt.x = r.get<float>();
        kp.pt.y = r.get<float>();
        kp.size = r.get<float>();
        kp.angle = r.get<float>();
        kp.response = r.get<float>();
        const auto level = r.get<int32_t>();
        kp.octave = level & 0xff;
        kp.class_id = (level & 0x100) ? features::kWeakCorner : -1;
        if ((level & ~0x1ff) != 0 || kp.octave > 31) r.corrupt("keypoint level");
        f.keypoints.push_back(kp);
        const double x = r.finite("keypoint"), y = r.finite("keypoint");
        f.points.emplace_back(x, y);
        r.bytes(f.descriptors.ptr<uint8_t>(static_cast<int>(i)), 32);
      }
      f.buildGrid();
      auto kf = std::make_shared<core::KeyFrame>(id, std::move(f), T_cw);
      if (vocabulary) vocabulary->transform(kf->frame.descriptors, kf->bow, kf->bow_features);
      if (!map->keyframes.emplace(id, kf).second) r.corrupt("duplicate keyframe");
      if (parent != core::kNoId) parents.emplace_back(kf.get(), parent);
      loops.emplace_back(kf.get(), std::move(loop_ids));
      covisibility.emplace_back(kf.get(), std::move(covisible));
    }
    for (uint32_t k = 0; k < point_count; ++k) {
      const auto id = r.get<core::Id>();
      Eigen::Vector3d pos;
      for (int i = 0; i < 3; ++i) pos[i] = r.finite("point position");
      const auto first = r.get<core::Id>();
      auto p = std::make_shared<core::MapPoint>(id, pos, first);
      p->descriptor = cv::Mat(1, 32, CV_8U);
      r.bytes(p->descriptor.ptr<uint8_t>(), 32);
      for (int i = 0; i < 3; ++i) p->normal[i] = r.finite("point normal");
      p->min_distance = r.finite("point distance");
      p->max_distance = r.finite("point distance");
      p->visible = r.get<int32_t>();
      p->found = r.get<int32_t>();
      const uint32_t n = r.count(10'000'000, "observation");
      for (uint32_t o = 0; o < n; ++o) {
        const auto kf_id = r.get<core::Id>();
        const auto idx = r.get<int32_t>();
        auto it = map->keyframes.find(kf_id);
        if (it == map->keyframes.end() || idx < 0 || static_cast<size_t>(idx) >= it->second->points.size())
          r.corrupt("observation");
        core::Map::observe(*it->second, idx, p);
      }
      if (!map->points.emplace(id, p).second) r.corrupt("duplicate point");
    }
    auto find = [&](core::Id id) -> core::KeyFrame* {
      auto it = map->keyframes.find(id);
      if (it == map->keyframes.end()) r.corrupt("keyframe link");
      return it->second.get();
    };
    for (auto& [kf, parent] : parents) {
      kf->parent = find(parent);
      kf->parent->children.insert(kf);
    }
    // A tree: every parent chain ends (loop correction and merging walk it from each keyframe).
    // Each chain is walked until a keyframe already known to lead to a root.
    std::unordered_set<const core::KeyFrame*> rooted;
    for (const auto& [kf, parent] : parents) {
      std::unordered_set<const core::KeyFrame*> chain;
      for (const core::KeyFrame* k = kf; k && !rooted.count(k); k = k->parent)
        if (!chain.insert(k).second) r.corrupt("spanning tree cycle");
      rooted.insert(chain.begin(), chain.end());
    }
    for (auto& [kf, ids] : loops)
      for (core::Id l : ids) kf->loop_edges.insert(find(l));
    if (origin != core::kNoId) map->origin = find(origin);
    for (auto& [kf, links] : covisibility)
      for (const auto& [n, weight] : links) kf->covisibility[find(n)] = weight;
    maps.push_back(map);
  }
  return maps;
}

}  // namespace hiveslam::io
