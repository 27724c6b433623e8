#pragma once
// A copy of a node's maps as the live view draws them: point positions with their map,
// keyframe poses, covisibility and loop edges. Taken one map at a time under that map's
// mutex, at the view's rate (at most a few times a second), never on the tracking thread.
#include <Eigen/Geometry>

#include <cstdint>
#include <memory>
#include <optional>
#include <vector>

namespace hiveslam::core {
class Map;
}

namespace hiveslam::viz {

// What is drawn of the keyframes: line segments as pairs of ends, in the map frame.
struct SceneLines {
  std::vector<Eigen::Vector3f> frusta, covisibility, loops;
};

struct MapScene {
  struct Point {
    float x = 0, y = 0, z = 0;
    uint64_t map = 0;
  };
  struct KeyFrame {
    uint64_t id = 0, map = 0;
    Eigen::Isometry3f T_wc = Eigen::Isometry3f::Identity();
  };
  struct Edge {
    uint32_t a = 0, b = 0;  // indices into keyframes
  };
  std::vector<Point> points;
  std::vector<KeyFrame> keyframes;
  std::vector<Edge> covisibility, loops;
  // Set where the keyframes are known only as drawn (a scene read from ROS markers).
  std::optional<SceneLines> lines;
  // Changes whenever the maps do (keyframes or points added or erased, a correction): a view
  // sends the scene again only when it changed.
  uint64_t fingerprint = 0;
};

// Covisibility edges drawn: between keyframes sharing at least this many points (ORB-SLAM's
// viewer draws the same threshold; fewer turns the map into a hairball).
constexpr int kDrawnCovisibility = 100;

MapScene captureScene(const std::vector<std::shared_ptr<core::Map>>& maps, int min_covisibility = kDrawnCovisibility);

// A frustum per keyframe (a thirtieth of the keyframes' spread: visible in a room and in a
// street alike) and the edges; `lines` as they are when set.
SceneLines sceneLines(const MapScene& scene);

// What captureScene would fingerprint, without copying: keyframe and point counts and epochs,
// read under each map's mutex (cheap: a view polls it before deciding to copy).
uint64_t sceneFingerprint(const std::vector<std::shared_ptr<core::Map>>& maps);

// A 32-bit label of a 64-bit map id (PointCloud2 has no 64-bit integer field type): the fold
// of its two halves, distinct for the ids one node makes (its counter sits in the low bits).
uint32_t mapLabel(uint64_t map);

}  // namespace hiveslam::viz
