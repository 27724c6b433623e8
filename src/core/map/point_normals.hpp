#pragma once
// Surface normals of map points from the points around them: the plane through a point that most
// of its nearest neighbours lie on. Patch alignment needs the slant of the surface a point lies on
// to warp its reference patch into another view; the fronto-parallel guess is off by 30-70
// degrees on a wall passed at a grazing angle, and that error follows the view: it bent sweep's
// maps through the turn as much as re-detected corners do. Normals off by 5 degrees at random
// cost little.
//
// The plane is found by consensus, not fitted to the whole neighbourhood: a point near the edge
// of a wall and the floor, or of a box, has neighbours on both faces, and a least-squares plane
// through all of them is neither face (a fifth of sweep's points got none, or one tilted by
// tens of degrees).
#include <Eigen/Core>
#include <optional>
#include <vector>

namespace hiveslam::core {

struct PlaneNormalOptions {
  int neighbours = 30;            // the support a plane is counted over
  int candidate_neighbours = 16;  // planes tried: through the point and two of these nearest
  double inlier_distance = 0.1;   // on a plane: within this many median neighbour distances of it
  double refit_band = 2.0;        // the refit's band, in inlier distances (point_normals.cpp)
  // Neighbours a plane must hold, the point itself not counted. In a loose cloud a plane through
  // the point holds about 4 of 30 by chance; near an edge a face holds about half.
  int min_inliers = 13;
  // The spread across the plane over the spread along it (smallest over middle eigenvalue of the
  // refit's points) above which they are not taken for a plane.
  double max_flatness = 0.15;
};

// One entry per point: the unit normal of its plane (sign arbitrary), or nothing where there are
// too few points or no plane through the point holds enough of them (a loose cloud, a curved
// surface). Exact neighbour search in a kd-tree.
std::vector<std::optional<Eigen::Vector3d>> planeNormals(const std::vector<Eigen::Vector3d>& points,
                                                         const PlaneNormalOptions& options = {});

}  // namespace hiveslam::core
