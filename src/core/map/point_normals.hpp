#pragma once
// Surface normals of map points from the points around them: the plane through a point and its
// nearest neighbours, where they are flat. Patch alignment needs the slant of the surface a point
// lies on to warp its reference patch into another view; the fronto-parallel guess is off by
// 30-70 degrees on a wall passed at a grazing angle, and that error follows the view: it bent
// sweep's maps through the turn as much as re-detected corners do. Normals off by 5 degrees at
// random cost little (docs/BENCHMARKS.md, session 47).
#include <Eigen/Core>
#include <optional>
#include <vector>

namespace hiveslam::core {

struct PlaneNormalOptions {
  int neighbours = 15;
  // The spread across the plane over the spread along it (smallest over middle eigenvalue of the
  // neighbourhood's scatter) above which the neighbourhood is not taken for a plane.
  double max_flatness = 0.15;
};

// One entry per point: the unit normal of its neighbourhood's plane (sign arbitrary), or nothing
// where there are too few points or they are not flat (an edge, a corner, a curved surface).
// Exact neighbour search in a kd-tree.
std::vector<std::optional<Eigen::Vector3d>> planeNormals(const std::vector<Eigen::Vector3d>& points,
                                                         const PlaneNormalOptions& options = {});

}  // namespace hiveslam::core
