#pragma once
// The world a synthetic sequence is rendered from: a textured room (floor, ceiling, four
// walls) with boxes standing on the floor and pillars from floor to ceiling, so that views
// have parallax and occlusion. World frame: z up, floor at z = 0.
#include <Eigen/Core>
#include <optional>
#include <random>
#include <string>
#include <vector>

#include "synth/texture.hpp"

namespace hiveslam::synth {

struct Box {
  Eigen::Vector2d center;   // of its footprint
  Eigen::Vector3d half;     // half sizes along its own axes; it rises from z = base to base + 2 half.z
  double base = 0.0;        // height of its bottom face (a table top stands on legs)
  int texture = 0;          // first of its 6 face textures: -x +x -y +y -z +z
  // Rotation about z, kept as cosine and sine: every ray needs them.
  double cos_yaw = 1.0, sin_yaw = 0.0;
  void setYaw(double yaw);
  double midHeight() const { return base + half.z(); }
};

struct Pillar {
  Eigen::Vector2d center;
  double radius = 0.2;
  int texture = 0;
};

struct Hit {
  double t = 0.0;             // ray parameter (depth along the camera z axis for our rays)
  int texture = -1;
  double u = 0.0, v = 0.0;    // surface coordinates, metres
  Eigen::Vector3d normal;     // unit, facing the ray
  Eigen::Vector3d axis_u, axis_v;  // surface directions of increasing u and v
};

// A lamp: irradiance power / d^2 on surfaces facing it (no shadows).
struct Light {
  Eigen::Vector3d position;
  double power = 1.0;
};

struct Scene {
  Eigen::Vector3d room_min, room_max;  // inside of the room
  std::vector<Box> boxes;
  std::vector<Pillar> pillars;
  std::vector<Texture> textures;  // room faces first: -x +x -y +y floor ceiling
  // Without lights, one distant light and a constant ambient term; with them, the shading of
  // each point adds up the lamps, so the brightness varies across the room.
  std::vector<Light> lights;
  double ambient = 0.0;  // irradiance every surface gets with lights on

  // How much light a point with (unit, ray-facing) normal n receives: about 1 on average.
  double shading(const Eigen::Vector3d& p, const Eigen::Vector3d& n) const;

  // Nearest surface along origin + t dir with t > 0; nullopt only for rays that leave the room
  // (impossible from inside).
  std::optional<Hit> intersect(const Eigen::Vector3d& origin, const Eigen::Vector3d& dir) const;
  // Whether a point is free space at least `clearance` metres from every obstacle and wall.
  bool isFree(const Eigen::Vector3d& p, double clearance) const;
};

struct SceneOptions {
  Eigen::Vector3d room_size{10.0, 8.0, 3.0};
  // A lived-in room instead of the textured box: plain painted walls and ceiling with a few
  // pictures, a low-contrast floor, tables with objects on them, shelves, cupboards and boxes
  // textured from `photos` (procedural where none), lit by ceiling lamps.
  bool furnished = false;
  int boxes = 6;
  int pillars = 3;
  double texel_density = 300.0;        // texels per metre
  std::vector<cv::Mat> photos;          // when non-empty, textures come from these photos
};

// Places obstacles at random (per rng) while keeping `keep_clear` points (the camera path)
// at least 0.6 m away from every obstacle, then textures every surface.
Scene makeScene(const SceneOptions& options, const std::vector<Eigen::Vector3d>& keep_clear,
                std::mt19937_64& rng);

}  // namespace hiveslam::synth
