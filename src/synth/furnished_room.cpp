#include "synth/furnished_room.hpp"

#include <cmath>

namespace hiveslam::synth {

namespace {

double uniform(std::mt19937_64& rng, double a, double b) { return std::uniform_real_distribution<double>(a, b)(rng); }

enum class Surface { Plain, Faded, Photo };

struct Piece {
  Box box;
  Surface look = Surface::Photo;
  double grey = 180;  // paint of a plain piece
};

// A piece standing against one of the four walls (chosen at random), its back 2 cm off it.
Box againstWall(const Scene& scene, Eigen::Vector3d half, double base, std::mt19937_64& rng) {
  const int wall = static_cast<int>(uniform(rng, 0, 4)) % 4;
  const bool along_x = wall >= 2;  // the walls at -y and +y run along x
  if (!along_x) std::swap(half.x(), half.y());
  Box b;
  b.half = half;
  b.base = base;
  b.setYaw(0.0);
  const Eigen::Vector3d& lo = scene.room_min;
  const Eigen::Vector3d& hi = scene.room_max;
  if (along_x) {
    b.center.x() = uniform(rng, lo.x() + half.x() + 0.1, hi.x() - half.x() - 0.1);
    b.center.y() = wall == 2 ? lo.y() + half.y() + 0.02 : hi.y() - half.y() - 0.02;
  } else {
    b.center.y() = uniform(rng, lo.y() + half.y() + 0.1, hi.y() - half.y() - 0.1);
    b.center.x() = wall == 0 ? lo.x() + half.x() + 0.02 : hi.x() - half.x() - 0.02;
  }
  return b;
}

}  // namespace

void furnishRoom(Scene& scene, const SceneOptions& o, const std::function<bool(const Scene&)>& clear,
                 std::mt19937_64& rng) {
  std::vector<Piece> pieces;
  // Places a group of boxes (a table and its legs, or one piece) if the path stays clear of it.
  auto place = [&](const std::vector<Piece>& group) {
    Scene trial = scene;
    for (const Piece& p : group) trial.boxes.push_back(p.box);
    if (!clear(trial)) return false;
    for (const Piece& p : group) {
      scene.boxes.push_back(p.box);
      pieces.push_back(p);
    }
    return true;
  };
  const Eigen::Vector3d inner = (scene.room_max - scene.room_min) / 2 - Eigen::Vector3d::Constant(0.6);
  // Tables with their legs, and objects on each (books, a keyboard, cups: photo-textured boxes).
  for (int placed = 0, tries = 0; placed < 3 && tries < 400; ++tries) {
    Box top;
    top.center = {uniform(rng, -inner.x(), inner.x()), uniform(rng, -inner.y(), inner.y())};
    top.half = {uniform(rng, 0.5, 0.8), uniform(rng, 0.35, 0.5), 0.02};
    top.base = 0.72;
    top.setYaw(uniform(rng, 0, M_PI));
    std::vector<Piece> group{{top, uniform(rng, 0, 1) < 0.5 ? Surface::Plain : Surface::Faded, uniform(rng, 120, 200)}};
    for (int cx : {-1, 1})
      for (int cy : {-1, 1}) {
        Box leg;
        const Eigen::Vector2d local(cx * (top.half.x() - 0.05), cy * (top.half.y() - 0.05));
        leg.center = top.center + Eigen::Vector2d(top.cos_yaw * local.x() - top.sin_yaw * local.y(),
                                                  top.sin_yaw * local.x() + top.cos_yaw * local.y());
        leg.half = {0.025, 0.025, 0.36};
        leg.setYaw(std::atan2(top.sin_yaw, top.cos_yaw));
        group.push_back({leg, Surface::Plain, 60});
      }
    const int objects = static_cast<int>(uniform(rng, 5, 9));
    for (int k = 0; k < objects; ++k) {
      Box obj;
      const Eigen::Vector2d local(uniform(rng, -0.8, 0.8) * (top.half.x() - 0.15), uniform(rng, -0.8, 0.8) * (top.half.y() - 0.12));
      obj.center = top.center + Eigen::Vector2d(top.cos_yaw * local.x() - top.sin_yaw * local.y(),
                                                top.sin_yaw * local.x() + top.cos_yaw * local.y());
      obj.half = {uniform(rng, 0.04, 0.14), uniform(rng, 0.04, 0.12), uniform(rng, 0.02, 0.14)};
      obj.base = top.base + 2 * top.half.z();
      obj.setYaw(uniform(rng, 0, M_PI));
      group.push_back({obj, Surface::Photo});
    }
    placed += place(group);
  }
  // Shelves of books, cupboards with plain doors, pictures: against the walls.
  for (int placed = 0, tries = 0; placed < 4 && tries < 300; ++tries)
    placed += place({{againstWall(scene, {uniform(rng, 0.4, 0.6), 0.18, uniform(rng, 0.7, 1.0)}, 0.0, rng), Surface::Photo}});
  for (int placed = 0, tries = 0; placed < 2 && tries < 300; ++tries)
    placed += place({{againstWall(scene, {uniform(rng, 0.4, 0.7), 0.3, 0.45}, 0.0, rng), Surface::Plain,
                      uniform(rng, 150, 220)}});
  // Pictures, posters, a whiteboard, a window: what hangs on the walls of a room in use.
  for (int placed = 0, tries = 0; placed < 8 && tries < 400; ++tries)
    placed += place({{againstWall(scene, {uniform(rng, 0.25, 0.6), 0.01, uniform(rng, 0.18, 0.45)}, uniform(rng, 0.9, 1.4), rng),
                      Surface::Photo}});
  // Boxes on the floor.
  for (int placed = 0, tries = 0; placed < 4 && tries < 400; ++tries) {
    Box b;
    b.center = {uniform(rng, -inner.x(), inner.x()), uniform(rng, -inner.y(), inner.y())};
    b.half = {uniform(rng, 0.15, 0.35), uniform(rng, 0.15, 0.35), uniform(rng, 0.1, 0.3)};
    b.setYaw(uniform(rng, 0, M_PI));
    placed += place({{b, Surface::Photo}});
  }

  // Textures: room faces (-x +x -y +y floor ceiling), then 6 per box.
  auto photo = [&](double w, double h, double contrast) {
    return o.photos.empty() ? makeProceduralTexture(w, h, o.texel_density, rng)
                            : makePhotoTexture(w, h, o.texel_density, o.photos, rng, contrast);
  };
  const Eigen::Vector3d r = scene.room_max - scene.room_min;
  const double wall_grey = uniform(rng, 170, 215);
  // Paint needs fewer texels: it holds no detail to filter.
  const double paint_density = std::min(o.texel_density, 100.0);
  for (int wall = 0; wall < 4; ++wall)
    scene.textures.push_back(makePlainTexture(wall < 2 ? r.y() : r.x(), r.z(), paint_density, wall_grey, rng));
  scene.textures.push_back(photo(r.x(), r.y(), 0.5));  // floor
  scene.textures.push_back(makePlainTexture(r.x(), r.y(), paint_density, wall_grey + 15, rng));
  for (size_t i = 0; i < scene.boxes.size(); ++i) {
    Box& b = scene.boxes[i];
    const Piece& piece = pieces[i];
    b.texture = static_cast<int>(scene.textures.size());
    const Eigen::Vector3d s = 2 * b.half;
    for (int axis = 0; axis < 3; ++axis) {
      const int ua = axis == 0 ? 1 : 0, va = axis == 2 ? 1 : 2;
      for (int side = 0; side < 2; ++side)
        scene.textures.push_back(piece.look == Surface::Plain ? makePlainTexture(s[ua], s[va], o.texel_density, piece.grey, rng)
                                 : piece.look == Surface::Faded ? photo(s[ua], s[va], 0.5)
                                                                : photo(s[ua], s[va], 1.0));
    }
  }
  // Two or three lamps under the ceiling; the ambient light of the walls.
  const int lamps = static_cast<int>(uniform(rng, 2, 4));
  for (int k = 0; k < lamps; ++k)
    scene.lights.push_back({{uniform(rng, -inner.x(), inner.x()), uniform(rng, -inner.y(), inner.y()), r.z() - 0.4},
                            uniform(rng, 3.0, 6.0)});
  scene.ambient = 0.25;
}

}  // namespace hiveslam::synth
