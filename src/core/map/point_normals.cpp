#include "core/map/point_normals.hpp"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <opencv2/flann.hpp>

namespace hiveslam::core {

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
  // The point itself is the nearest (distance 0): k neighbours are the first k + 1.
  tree.knnSearch(cloud, indices, distances, static_cast<int>(k + 1), cv::flann::SearchParams(cvflann::FLANN_CHECKS_UNLIMITED));
  for (size_t i = 0; i < points.size(); ++i) {
    const int* near = indices.ptr<int>(static_cast<int>(i));
    Eigen::Vector3d mean = Eigen::Vector3d::Zero();
    for (size_t a = 0; a <= k; ++a) mean += points[static_cast<size_t>(near[a])];
    mean /= static_cast<double>(k + 1);
    Eigen::Matrix3d scatter = Eigen::Matrix3d::Zero();
    for (size_t a = 0; a <= k; ++a) {
      const Eigen::Vector3d d = points[static_cast<size_t>(near[a])] - mean;
      scatter.noalias() += d * d.transpose();
    }
    const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(scatter);  // eigenvalues ascending
    if (eig.info() != Eigen::Success || eig.eigenvalues()(1) <= 0) continue;
    if (eig.eigenvalues()(0) <= options.max_flatness * eig.eigenvalues()(1)) out[i] = eig.eigenvectors().col(0);
  }
  return out;
}

}  // namespace hiveslam::core
