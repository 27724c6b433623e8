#include "viz/map_scene.hpp"

#include <algorithm>
#include <unordered_map>

#include "core/map/map.hpp"

namespace hiveslam::viz {

namespace {

uint64_t mix(uint64_t h, uint64_t v) { return (h ^ v) * 0x100000001b3ull + (h >> 29); }

}  // namespace

uint64_t sceneFingerprint(const std::vector<std::shared_ptr<core::Map>>& maps) {
  uint64_t h = 0xcbf29ce484222325ull;
  for (const auto& m : maps) {
    std::lock_guard lock(m->mutex);
    h = mix(h, m->id);
    h = mix(h, m->keyframes.size());
    h = mix(h, m->points.size());
    h = mix(h, m->epoch);
  }
  return h;
}

MapScene captureScene(const std::vector<std::shared_ptr<core::Map>>& maps, int min_covisibility) {
  MapScene s;
  std::unordered_map<const core::KeyFrame*, uint32_t> index;
  uint64_t h = 0xcbf29ce484222325ull;
  for (const auto& m : maps) {
    std::lock_guard lock(m->mutex);
    h = mix(mix(mix(mix(h, m->id), m->keyframes.size()), m->points.size()), m->epoch);
    s.points.reserve(s.points.size() + m->points.size());
    for (const auto& [id, p] : m->points) {
      if (p->bad) continue;
      s.points.push_back({static_cast<float>(p->position.x()), static_cast<float>(p->position.y()),
                          static_cast<float>(p->position.z()), m->id});
    }
    const size_t first = s.keyframes.size();
    for (const auto& [id, kf] : m->keyframes) {
      if (kf->bad) continue;
      index[kf.get()] = static_cast<uint32_t>(s.keyframes.size());
      s.keyframes.push_back({kf->id, m->id, kf->T_cw.inverse().cast<float>()});
    }
    // Each edge once: from the keyframe with the lower index, within this map.
    for (size_t i = first; i < s.keyframes.size(); ++i) {
      const auto& kf = m->keyframes.at(s.keyframes[i].id);
      for (const auto& [other, weight] : kf->covisibility) {
        const auto it = index.find(other);
        if (weight >= min_covisibility && it != index.end() && it->second >= first && it->second > i)
          s.covisibility.push_back({static_cast<uint32_t>(i), it->second});
      }
      for (const core::KeyFrame* other : kf->loop_edges) {
        const auto it = index.find(other);
        if (it != index.end() && it->second >= first && it->second > i) s.loops.push_back({static_cast<uint32_t>(i), it->second});
      }
    }
  }
  s.fingerprint = h;
  return s;
}

SceneLines sceneLines(const MapScene& scene) {
  if (scene.lines) return *scene.lines;
  SceneLines l;
  Eigen::AlignedBox3f box;
  for (const auto& k : scene.keyframes) box.extend(k.T_wc.translation());
  const float size = scene.keyframes.empty() ? 0.05f : std::max(box.diagonal().norm() / 30.0f, 1e-3f);
  const float w = size, h = size * 0.75f, d = size * 0.8f;
  const float xy[4][2] = {{-w, -h}, {w, -h}, {w, h}, {-w, h}};
  l.frusta.reserve(scene.keyframes.size() * 16);
  for (const auto& k : scene.keyframes) {
    const Eigen::Vector3f c = k.T_wc.translation();
    Eigen::Vector3f corner[4];
    for (int i = 0; i < 4; ++i) corner[i] = k.T_wc * Eigen::Vector3f(xy[i][0], xy[i][1], d);
    for (int i = 0; i < 4; ++i) {
      l.frusta.push_back(c);
      l.frusta.push_back(corner[i]);
      l.frusta.push_back(corner[i]);
      l.frusta.push_back(corner[(i + 1) % 4]);
    }
  }
  for (const auto& e : scene.covisibility) {
    l.covisibility.push_back(scene.keyframes[e.a].T_wc.translation());
    l.covisibility.push_back(scene.keyframes[e.b].T_wc.translation());
  }
  for (const auto& e : scene.loops) {
    l.loops.push_back(scene.keyframes[e.a].T_wc.translation());
    l.loops.push_back(scene.keyframes[e.b].T_wc.translation());
  }
  return l;
}

uint32_t mapLabel(uint64_t map) { return static_cast<uint32_t>(map ^ (map >> 32)); }

}  // namespace hiveslam::viz
