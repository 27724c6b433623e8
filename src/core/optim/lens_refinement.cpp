#include "core/optim/lens_refinement.hpp"

#include <ceres/ceres.h>

#include <algorithm>
#include <cmath>

namespace hiveslam::core {

namespace {

constexpr double kChi2 = 5.991;  // 95% of chi-square with 2 degrees of freedom

struct LensReprojection {
  Eigen::Vector2d uv;
  double inv_sigma;

  template <class T>
  bool operator()(const T* q, const T* t, const T* p, const T* lens, T* r) const {
    const Eigen::Map<const Eigen::Quaternion<T>> q_cw(q);
    const Eigen::Map<const Eigen::Matrix<T, 3, 1>> t_cw(t), p_w(p);
    const Eigen::Matrix<T, 3, 1> pc = q_cw * p_w + t_cw;
    if (pc.z() <= T(1e-9)) return false;
    const T x = pc.x() / pc.z(), y = pc.y() / pc.z();
    const T d = T(1) + lens[4] * (x * x + y * y);
    r[0] = (lens[0] * x * d + lens[2] - T(uv.x())) * T(inv_sigma);
    r[1] = (lens[1] * y * d + lens[3] - T(uv.y())) * T(inv_sigma);
    return true;
  }
};

double chi2(const BaObservation& o, const BaPose& pose, const BaPoint& point, const double* lens) {
  double r[2];
  const LensReprojection f{o.uv, o.inv_sigma};
  if (!f(pose.q_cw.coeffs().data(), pose.t_cw.data(), point.p_w.data(), lens, r)) return 1e9;
  return r[0] * r[0] + r[1] * r[1];
}

}  // namespace

BaProblem rawObservations(const MapBaProblem& map) {
  BaProblem raw = map.problem;
  for (size_t i = 0; i < raw.observations.size(); ++i) {
    const auto& [kf, idx] = map.sources[i];
    const cv::Point2f& pt = kf->frame.keypoints[static_cast<size_t>(idx)].pt;
    raw.observations[i].uv = Eigen::Vector2d(pt.x, pt.y);
  }
  return raw;
}

LensRefinement refineLens(const BaProblem& problem, const LensParameters& start, const LensRefinementOptions& options) {
  LensRefinement out;
  out.lens = start;
  std::vector<int> seen(problem.points.size(), 0);
  for (const BaObservation& o : problem.observations) ++seen[static_cast<size_t>(o.point)];
  std::vector<const BaObservation*> used;
  for (const BaObservation& o : problem.observations)
    if (seen[static_cast<size_t>(o.point)] >= options.min_observations) used.push_back(&o);
  if (problem.poses.size() < 3 || used.size() < 100) return out;

  std::vector<BaPose> poses = problem.poses;
  std::vector<BaPoint> points = problem.points;
  double lens[5] = {start.fx, start.fy, start.cx, start.cy, start.k1};
  auto rms = [&](const std::vector<bool>& skip) {
    double sum = 0;
    int n = 0;
    for (size_t i = 0; i < used.size(); ++i) {
      if (skip[i]) continue;
      const BaObservation& o = *used[i];
      sum += chi2(o, poses[static_cast<size_t>(o.pose)], points[static_cast<size_t>(o.point)], lens);
      ++n;
    }
    return n ? std::sqrt(sum / n) : 0.0;
  };
  std::vector<bool> outlier(used.size(), false);
  out.rms_before_px = rms(outlier);

  for (int round = 0; round < 2; ++round) {
    ceres::Problem ceres_problem;
    ceres::Manifold* quaternion = new ceres::EigenQuaternionManifold;
    bool quaternion_owned = true;
    for (size_t i = 0; i < used.size(); ++i) {
      if (outlier[i]) continue;
      const BaObservation& o = *used[i];
      BaPose& pose = poses[static_cast<size_t>(o.pose)];
      auto* cost = new ceres::AutoDiffCostFunction<LensReprojection, 2, 4, 3, 3, 5>(new LensReprojection{o.uv, o.inv_sigma});
      ceres_problem.AddResidualBlock(cost, new ceres::HuberLoss(std::sqrt(kChi2)), pose.q_cw.coeffs().data(), pose.t_cw.data(),
                                     points[static_cast<size_t>(o.point)].p_w.data(), lens);
    }
    int held = 0;
    for (BaPose& pose : poses) {
      double* q = pose.q_cw.coeffs().data();
      if (!ceres_problem.HasParameterBlock(q)) continue;
      ceres_problem.SetManifold(q, quaternion);
      quaternion_owned = false;
      // The gauge: the two lowest poses with observations hold the map's position, rotation and scale.
      if (held < 2) {
        ceres_problem.SetParameterBlockConstant(q);
        ceres_problem.SetParameterBlockConstant(pose.t_cw.data());
        ++held;
      }
    }
    if (quaternion_owned) delete quaternion;
    ceres::Solver::Options solver;
    solver.linear_solver_type = ceres::SPARSE_SCHUR;
    solver.max_num_iterations = options.iterations;
    solver.num_threads = 1;
    ceres::Solver::Summary summary;
    ceres::Solve(solver, &ceres_problem, &summary);
    out.converged = summary.termination_type == ceres::CONVERGENCE;
    if (round == 0)
      for (size_t i = 0; i < used.size(); ++i) {
        const BaObservation& o = *used[i];
        outlier[i] = chi2(o, poses[static_cast<size_t>(o.pose)], points[static_cast<size_t>(o.point)], lens) > kChi2;
      }
  }
  out.lens = {lens[0], lens[1], lens[2], lens[3], lens[4]};
  out.observations = static_cast<int>(used.size());
  out.outliers = static_cast<int>(std::count(outlier.begin(), outlier.end(), true));
  out.rms_after_px = rms(outlier);
  return out;
}

}  // namespace hiveslam::core
