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
  Eigen::Vector2d center;   // on the floor
  Eigen::Vector3d half;     // half sizes along its own axes; it rises from z = 0 to 2 half.z
  int texture = 0;          // first of its 6 face textures: -x +x -y +y -z +z
  // Rotation about z, kept as cosine and sine: every ray needs them.
  double cos_yaw = 1.0, sin_yaw = 0.0;
  void setYaw(double yaw);
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

struct Scene {
  Eigen::Vector3d room_min, room_max;  // inside of the room
  std::vector<Box> boxes;
  std::vector<Pillar> pillars;
  std::vector<Texture> textures;  // room faces first: -x +x -y +y floor ceiling

  // Nearest surface along origin + t dir with t > 0; nullopt only for rays that leave the room
  // (impossible from inside).
  std::optional<Hit> intersect(const Eigen::Vector3d& origin, const Eigen::Vector3d& dir) const;
  // Whether a point is free space at least `clearance` metres from every obstacle and wall.
  bool isFree(const Eigen::Vector3d& p, double clearance) const;
};

struct SceneOptions {
  Eigen::Vector3d room_size{10.0, 8.0, 3.0};
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
