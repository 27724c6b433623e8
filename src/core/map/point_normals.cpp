#include "core/map/point_normals.hpp"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <opencv2/flann.hpp>

namespace hiveslam::core {

namespace {

// The least-squares plane of the point (the origin) and the offsets within `band` of the plane
// `n` through it, where they are flat. The band is wider than the consensus's: a plane through
// the point itself is tilted by the point's own noise, and a band that narrow would keep the
// tilt (those of the face's points that happen to lie along it).
std::optional<Eigen::Vector3d> refit(const std::vector<Eigen::Vector3d>& d, const Eigen::Vector3d& n, double band,
                                     const PlaneNormalOptions& options) {
  std::vector<Eigen::Vector3d> on{Eigen::Vector3d::Zero()};
  for (const Eigen::Vector3d& q : d)
    if (std::abs(n.dot(q)) < band) on.push_back(q);
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  for (const Eigen::Vector3d& q : on) mean += q;
  mean /= static_cast<double>(on.size());
  Eigen::Matrix3d scatter = Eigen::Matrix3d::Zero();
  for (const Eigen::Vector3d& q : on) scatter.noalias() += (q - mean) * (q - mean).transpose();
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(scatter);  // eigenvalues ascending
  if (eig.info() != Eigen::Success || eig.eigenvalues()(1) <= 0) return std::nullopt;
  if (eig.eigenvalues()(0) > options.max_flatness * eig.eigenvalues()(1)) return std::nullopt;
  return Eigen::Vector3d(eig.eigenvectors().col(0));
}

// The plane through the origin (the point) that most of the offsets `d` lie on, refitted to
// them; nothing where too few do.
std::optional<Eigen::Vector3d> consensusPlane(const std::vector<Eigen::Vector3d>& d, const PlaneNormalOptions& options) {
  const size_t k = d.size();
  std::vector<double> length(k);
  for (size_t a = 0; a < k; ++a) length[a] = d[a].norm();
  std::vector<double> sorted = length;
  std::nth_element(sorted.begin(), sorted.begin() + static_cast<long>(k / 2), sorted.end());
  const double tolerance = options.inlier_distance * sorted[k / 2];
  if (!(tolerance > 0)) return std::nullopt;
  // Offsets come nearest first: candidates through the point and two of the nearest few.
  const size_t c = std::min(k, static_cast<size_t>(std::max(options.candidate_neighbours, 2)));
  int best = 0;
  double best_cost = 0.0;
  Eigen::Vector3d best_n = Eigen::Vector3d::Zero();
  // A plane that holds nearly all of them is the face: no other can hold more than the rest (this
  // ends the search early on a clean face).
  const int enough = static_cast<int>(std::ceil(0.9 * static_cast<double>(k)));
  for (size_t a = 0; a < c && best < enough; ++a)
    for (size_t b = a + 1; b < c && best < enough; ++b) {
      Eigen::Vector3d n = d[a].cross(d[b]);
      if (n.norm() < 0.2 * length[a] * length[b]) continue;  // within 12 degrees of one line
      n.normalize();
      int count = 0;
      double cost = 0.0;
      for (const Eigen::Vector3d& q : d) {
        const double e = std::abs(n.dot(q));
        if (e < tolerance) {
          ++count;
          cost += e;
        }
      }
      if (count > best || (count == best && cost < best_cost)) {
        best = count;
        best_cost = cost;
        best_n = n;
      }
    }
  if (best < options.min_inliers) return std::nullopt;
  return refit(d, best_n, options.refit_band * tolerance, options);
}

}  // namespace

std::vector<std::optional<Eigen::Vector3d>> planeNormals(const std::vector<Eigen::Vector3d>& points,
                                                         const PlaneNormalOptions& options) {
  std::vector<std::optional<Eigen::Vector3d>> out(points.size());
  const size_t k = static_cast<size_t>(std::max(options.neighbours, 3));
  if (points.size() <= k) return out;
  // Exact k-nearest search in a kd-tree (unlimited checks): the same neighbours as an exhaustive
  // search, in O(n log n) instead of O(n^2) (a second for 15,000 points before).
  cv::Mat cloud(static_cast<int>(points.size()), 3, CV_32F);
  for (size_t i = 0; i < points.size(); ++i)
    for (int c = 0; c < 3; ++c) cloud.at<float>(static_cast<int>(i), c) = static_cast<float>(points[i](c));
  cv::flann::Index tree(cloud, cv::flann::KDTreeIndexParams(1));
  cv::Mat indices, distances;
  // The point itself is the nearest (distance 0): k neighbours are the first k + 1, nearest first.
  tree.knnSearch(cloud, indices, distances, static_cast<int>(k + 1), cv::flann::SearchParams(cvflann::FLANN_CHECKS_UNLIMITED));
  std::vector<Eigen::Vector3d> offsets(k);
  for (size_t i = 0; i < points.size(); ++i) {
    const int* near = indices.ptr<int>(static_cast<int>(i));
    for (size_t a = 0; a < k; ++a) offsets[a] = points[static_cast<size_t>(near[a + 1])] - points[i];
    out[i] = consensusPlane(offsets, options);
  }
  return out;
}

}  // namespace hiveslam::core
