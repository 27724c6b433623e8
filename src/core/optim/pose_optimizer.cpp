#include "core/optim/pose_optimizer.hpp"

#include <ceres/ceres.h>

#include "core/optim/reprojection_error.hpp"

namespace hiveslam::core {

int optimizePose(const Intrinsics& K, const std::vector<PoseObservation>& obs, Eigen::Isometry3d& T_cw,
                 std::vector<bool>& outlier) {
  outlier.assign(obs.size(), false);
  if (obs.size() < 3) return 0;
  Eigen::Quaterniond q(T_cw.linear());
  Eigen::Vector3d t = T_cw.translation();
  constexpr double kChi2 = 5.991;
  int inliers = 0;
  for (int round = 0; round < 4; ++round) {
    ceres::Problem problem;
    int used = 0;
    for (size_t i = 0; i < obs.size(); ++i) {
      if (outlier[i]) continue;
      auto* cost = new ceres::AutoDiffCostFunction<PoseOnlyError, 2, 4, 3>(
          new PoseOnlyError(K, obs[i].uv, obs[i].inv_sigma, obs[i].point));
      // The last round runs without the robust kernel, on inliers only.
      problem.AddResidualBlock(cost, round < 3 ? new ceres::HuberLoss(std::sqrt(kChi2)) : nullptr, q.coeffs().data(),
                               t.data());
      ++used;
    }
    if (used < 3) break;
    problem.SetManifold(q.coeffs().data(), new ceres::EigenQuaternionManifold);
    ceres::Solver::Options options;
    options.linear_solver_type = ceres::DENSE_QR;
    options.max_num_iterations = 10;
    options.logging_type = ceres::SILENT;
    ceres::Solver::Summary summary;
    ceres::Solve(options, &problem, &summary);
    inliers = 0;
    for (size_t i = 0; i < obs.size(); ++i) {
      const Eigen::Vector3d pc = q * obs[i].point + t;
      const double chi2 = pc.z() <= 0 ? 1e9 : ((K.project(pc) - obs[i].uv) * obs[i].inv_sigma).squaredNorm();
      // Every round re-classifies all observations: an early outlier may come back.
      outlier[i] = chi2 > kChi2;
      if (!outlier[i]) ++inliers;
    }
    if (inliers < 10) break;
  }
  T_cw.linear() = q.normalized().toRotationMatrix();
  T_cw.translation() = t;
  return inliers;
}

}  // namespace hiveslam::core
