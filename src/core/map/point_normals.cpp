#include "core/map/point_normals.hpp"

#include <Eigen/Eigenvalues>
#include <algorithm>

namespace hiveslam::core {

std::vector<std::optional<Eigen::Vector3d>> planeNormals(const std::vector<Eigen::Vector3d>& points,
                                                         const PlaneNormalOptions& options) {
  std::vector<std::optional<Eigen::Vector3d>> out(points.size());
  const size_t k = static_cast<size_t>(std::max(options.neighbours, 3));
  if (points.size() <= k) return out;
  std::vector<std::pair<double, size_t>> by_distance(points.size());
  for (size_t i = 0; i < points.size(); ++i) {
    for (size_t j = 0; j < points.size(); ++j) by_distance[j] = {(points[j] - points[i]).squaredNorm(), j};
    // The point itself is the nearest (distance 0): k neighbours are the first k + 1.
    std::nth_element(by_distance.begin(), by_distance.begin() + static_cast<long>(k), by_distance.end());
    Eigen::Vector3d mean = Eigen::Vector3d::Zero();
    for (size_t a = 0; a <= k; ++a) mean += points[by_distance[a].second];
    mean /= static_cast<double>(k + 1);
    Eigen::Matrix3d scatter = Eigen::Matrix3d::Zero();
    for (size_t a = 0; a <= k; ++a) {
      const Eigen::Vector3d d = points[by_distance[a].second] - mean;
      scatter.noalias() += d * d.transpose();
    }
    const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(scatter);  // eigenvalues ascending
    if (eig.info() != Eigen::Success || eig.eigenvalues()(1) <= 0) continue;
    if (eig.eigenvalues()(0) <= options.max_flatness * eig.eigenvalues()(1)) out[i] = eig.eigenvectors().col(0);
  }
  return out;
}

}  // namespace hiveslam::core
