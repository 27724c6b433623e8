#include "synth/scene.hpp"

#include <Eigen/Geometry>
#include <cmath>
#include <limits>

#include "synth/furnished_room.hpp"

namespace hiveslam::synth {

namespace {

constexpr double kEps = 1e-9;

}  // namespace

namespace {

// Ray in a box's frame (origin at the centre of its footprint, at mid height).
struct BoxRay {
  Eigen::Vector3d o, d;
};
BoxRay toBox(const Box& b, const Eigen::Vector3d& o, const Eigen::Vector3d& d) {
  const double c = b.cos_yaw, s = b.sin_yaw;
  const Eigen::Vector3d rel(o.x() - b.center.x(), o.y() - b.center.y(), o.z() - b.midHeight());
  return {{c * rel.x() + s * rel.y(), -s * rel.x() + c * rel.y(), rel.z()},
          {c * d.x() + s * d.y(), -s * d.x() + c * d.y(), d.z()}};
}

// Entry distance into the box and the axis of the entry face; t <= 0 when missed.
double boxEntry(const Box& b, const BoxRay& r, int& axis) {
  double t_near = -std::numeric_limits<double>::infinity(), t_far = std::numeric_limits<double>::infinity();
  axis = -1;
  for (int i = 0; i < 3; ++i) {
    if (std::abs(r.d[i]) < kEps) {
      if (std::abs(r.o[i]) > b.half[i]) return -1.0;
      continue;
    }
    double t0 = (-b.half[i] - r.o[i]) / r.d[i], t1 = (b.half[i] - r.o[i]) / r.d[i];
    if (t0 > t1) std::swap(t0, t1);
    if (t0 > t_near) {
      t_near = t0;
      axis = i;
    }
    t_far = std::min(t_far, t1);
  }
  return axis >= 0 && t_near <= t_far ? t_near : -1.0;
}

double pillarEntry(const Pillar& p, const Eigen::Vector3d& o, const Eigen::Vector3d& d) {
  const double ox = o.x() - p.center.x(), oy = o.y() - p.center.y();
  const double a = d.x() * d.x() + d.y() * d.y();
  if (a < kEps) return -1.0;
  const double b = 2 * (ox * d.x() + oy * d.y());
  const double cc = ox * ox + oy * oy - p.radius * p.radius;
  const double disc = b * b - 4 * a * cc;
  if (disc < 0) return -1.0;
  return (-b - std::sqrt(disc)) / (2 * a);
}

}  // namespace

double Scene::shading(const Eigen::Vector3d& p, const Eigen::Vector3d& n) const {
  if (lights.empty()) {
    const Eigen::Vector3d light = Eigen::Vector3d(0.3, 0.5, 0.81).normalized();
    return 0.72 + 0.28 * std::abs(n.dot(light));
  }
  double e = ambient;
  for (const Light& l : lights) {
    const Eigen::Vector3d d = l.position - p;
    const double d2 = std::max(d.squaredNorm(), 0.04);
    const double cosine = n.dot(d) / std::sqrt(d2);
    if (cosine > 0) e += l.power * cosine / d2;
  }
  return e;
}

void Box::setYaw(double yaw) {
  cos_yaw = std::cos(yaw);
  sin_yaw = std::sin(yaw);
}

std::optional<Hit> Scene::intersect(const Eigen::Vector3d& o, const Eigen::Vector3d& d) const {
  // First find the nearest surface by distance alone; surface details only for the winner.
  enum class Kind { None, Room, Box, Pillar } kind = Kind::None;
  double best = std::numeric_limits<double>::infinity();
  int index = -1, axis = -1;
  bool positive = false;
  for (int i = 0; i < 3; ++i) {  // the room, seen from inside: the wall the ray leaves through
    if (std::abs(d[i]) < kEps) continue;
    const double ti = ((d[i] > 0 ? room_max[i] : room_min[i]) - o[i]) / d[i];
    if (ti > kEps && ti < best) {
      best = ti;
      kind = Kind::Room;
      axis = i;
      positive = d[i] > 0;
    }
  }
  const double dd = d.squaredNorm();
  for (size_t k = 0; k < boxes.size(); ++k) {
    // Bounding-sphere rejection first: most rays miss most boxes.
    const Box& b = boxes[k];
    const Eigen::Vector3d w(b.center.x() - o.x(), b.center.y() - o.y(), b.midHeight() - o.z());
    const double wd = w.dot(d);
    const double r2 = b.half.squaredNorm();
    if (wd < 0 && w.squaredNorm() > r2) continue;  // behind the ray origin
    if (w.squaredNorm() - wd * wd / dd > r2) continue;
    int a = -1;
    const double t = boxEntry(boxes[k], toBox(boxes[k], o, d), a);
    if (t > kEps && t < best) {
      best = t;
      kind = Kind::Box;
      index = static_cast<int>(k);
    }
  }
  for (size_t k = 0; k < pillars.size(); ++k) {
    const double t = pillarEntry(pillars[k], o, d);
    if (t <= kEps || t >= best) continue;
    const double z = o.z() + t * d.z();
    if (z < room_min.z() || z > room_max.z()) continue;
    best = t;
    kind = Kind::Pillar;
    index = static_cast<int>(k);
  }
  if (kind == Kind::None) return std::nullopt;

  Hit h;
  h.t = best;
  const Eigen::Vector3d p = o + best * d;
  if (kind == Kind::Room) {
    h.texture = 2 * axis + (positive ? 1 : 0);
    h.normal = Eigen::Vector3d::Zero();
    h.normal[axis] = positive ? -1.0 : 1.0;
    // Walls: u along the horizontal wall axis, v up. Floor and ceiling: u = x, v = y.
    const int ua = axis == 0 ? 1 : 0, va = axis == 2 ? 1 : 2;
    h.u = p[ua] - room_min[ua];
    h.v = p[va] - room_min[va];
    h.axis_u = Eigen::Vector3d::Unit(ua);
    h.axis_v = Eigen::Vector3d::Unit(va);
  } else if (kind == Kind::Box) {
    const Box& b = boxes[static_cast<size_t>(index)];
    const BoxRay r = toBox(b, o, d);
    boxEntry(b, r, axis);
    const bool from_positive = r.d[axis] < 0;  // entering through the +axis face
    h.texture = b.texture + 2 * axis + (from_positive ? 1 : 0);
    const Eigen::Vector3d lp = r.o + best * r.d;
    const int ua = axis == 0 ? 1 : 0, va = axis == 2 ? 1 : 2;
    h.u = lp[ua] + b.half[ua];
    h.v = lp[va] + b.half[va];
    const double c = b.cos_yaw, s = b.sin_yaw;
    auto toWorld = [&](const Eigen::Vector3d& v) {
      return Eigen::Vector3d(c * v.x() - s * v.y(), s * v.x() + c * v.y(), v.z());
    };
    Eigen::Vector3d n = Eigen::Vector3d::Zero();
    n[axis] = from_positive ? 1.0 : -1.0;
    h.normal = toWorld(n);
    h.axis_u = toWorld(Eigen::Vector3d::Unit(ua));
    h.axis_v = toWorld(Eigen::Vector3d::Unit(va));
  } else {
    const Pillar& q = pillars[static_cast<size_t>(index)];
    h.texture = q.texture;
    const double px = p.x() - q.center.x(), py = p.y() - q.center.y();
    const double phi = std::atan2(py, px);
    h.u = q.radius * (phi + M_PI);
    h.v = p.z() - room_min.z();
    h.normal = Eigen::Vector3d(px, py, 0).normalized();
    h.axis_u = Eigen::Vector3d(-std::sin(phi), std::cos(phi), 0);
    h.axis_v = Eigen::Vector3d::UnitZ();
  }
  return h;
}

bool Scene::isFree(const Eigen::Vector3d& p, double clearance) const {
  for (int i = 0; i < 3; ++i)
    if (p[i] < room_min[i] + clearance || p[i] > room_max[i] - clearance) return false;
  for (const Box& b : boxes) {
    const double c = b.cos_yaw, s = b.sin_yaw;
    const double rx = p.x() - b.center.x(), ry = p.y() - b.center.y();
    const Eigen::Vector3d l(c * rx + s * ry, -s * rx + c * ry, p.z() - b.midHeight());
    const Eigen::Vector3d outside = (l.cwiseAbs() - b.half).cwiseMax(0.0);
    if (outside.norm() < clearance) return false;
  }
  for (const Pillar& q : pillars)
    if ((p.head<2>() - q.center).norm() < q.radius + clearance) return false;
  return true;
}

Scene makeScene(const SceneOptions& o, const std::vector<Eigen::Vector3d>& keep_clear,
                std::mt19937_64& rng) {
  auto uni = [&](double a, double b) { return std::uniform_real_distribution<double>(a, b)(rng); };
  Scene scene;
  scene.room_min = Eigen::Vector3d(-o.room_size.x() / 2, -o.room_size.y() / 2, 0.0);
  scene.room_max = Eigen::Vector3d(o.room_size.x() / 2, o.room_size.y() / 2, o.room_size.z());
  constexpr double kClearance = 0.6;
  auto pathClear = [&](const Scene& s) {
    for (const auto& p : keep_clear)
      if (!s.isFree(p, kClearance)) return false;
    return true;
  };
  if (o.furnished) {
    furnishRoom(scene, o, pathClear, rng);
    return scene;
  }
  const Eigen::Vector3d inner = o.room_size / 2 - Eigen::Vector3d::Constant(0.5);
  for (int i = 0, tries = 0; i < o.boxes && tries < 400; ++tries) {
    Box b;
    b.center = {uni(-inner.x(), inner.x()), uni(-inner.y(), inner.y())};
    b.half = {uni(0.2, 0.6), uni(0.2, 0.6), uni(0.2, 0.7)};
    b.setYaw(uni(0, M_PI));
    Scene trial = scene;
    trial.boxes.push_back(b);
    if (!pathClear(trial)) continue;
    scene.boxes.push_back(b);
    ++i;
  }
  for (int i = 0, tries = 0; i < o.pillars && tries < 400; ++tries) {
    Pillar p;
    p.center = {uni(-inner.x(), inner.x()), uni(-inner.y(), inner.y())};
    p.radius = uni(0.12, 0.3);
    Scene trial = scene;
    trial.pillars.push_back(p);
    if (!pathClear(trial)) continue;
    scene.pillars.push_back(p);
    ++i;
  }
  // Textures: room faces (-x +x -y +y floor ceiling), then 6 per box, then 1 per pillar.
  auto make = [&](double w, double h) {
    return o.photos.empty() ? makeProceduralTexture(w, h, o.texel_density, rng)
                            : makePhotoTexture(w, h, o.texel_density, o.photos, rng);
  };
  const Eigen::Vector3d& r = o.room_size;
  scene.textures.push_back(make(r.y(), r.z()));
  scene.textures.push_back(make(r.y(), r.z()));
  scene.textures.push_back(make(r.x(), r.z()));
  scene.textures.push_back(make(r.x(), r.z()));
  scene.textures.push_back(make(r.x(), r.y()));
  scene.textures.push_back(make(r.x(), r.y()));
  for (Box& b : scene.boxes) {
    b.texture = static_cast<int>(scene.textures.size());
    const Eigen::Vector3d s = 2 * b.half;
    for (int axis = 0; axis < 3; ++axis) {
      const int ua = axis == 0 ? 1 : 0, va = axis == 2 ? 1 : 2;
      scene.textures.push_back(make(s[ua], s[va]));
      scene.textures.push_back(make(s[ua], s[va]));
    }
  }
  for (Pillar& p : scene.pillars) {
    p.texture = static_cast<int>(scene.textures.size());
    scene.textures.push_back(make(2 * M_PI * p.radius, r.z()));
  }
  return scene;
}

}  // namespace hiveslam::synth
