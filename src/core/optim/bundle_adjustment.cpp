#include "core/optim/bundle_adjustment.hpp"

#include <ceres/ceres.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include "core/optim/reprojection_error.hpp"

namespace hiveslam::core {

namespace {

constexpr double kMinCosOffAxis = 0.1;  // cos 84.3 deg

// An observation's reprojection error in units of its level sigma; infinite for a point
// beside or behind the camera (see below).
double levelError(const BaProblem& pb, const BaObservation& ob) {
  const auto& pose = pb.poses[static_cast<size_t>(ob.pose)];
  const Eigen::Vector3d pc = pose.q_cw * pb.points[static_cast<size_t>(ob.point)].p_w + pose.t_cw;
  if (pc.z() <= kMinCosOffAxis * pc.norm()) return std::numeric_limits<double>::infinity();
  return (pb.K.project(pc) - ob.uv).norm() * ob.inv_sigma;
}

class AbortCallback : public ceres::IterationCallback {
 public:
  explicit AbortCallback(const std::atomic<bool>* flag) : flag_(flag) {}
  ceres::CallbackReturnType operator()(const ceres::IterationSummary&) override {
    return flag_ && flag_->load() ? ceres::SOLVER_TERMINATE_SUCCESSFULLY : ceres::SOLVER_CONTINUE;
  }

 private:
  const std::atomic<bool>* flag_;
};

}  // namespace

BaSummary bundleAdjust(BaProblem& pb, const BaOptions& o) {
  // Each pose is one 7-parameter block (quaternion coefficients x, y, z, w, then t) on a 6-dof
  // manifold: one block per camera instead of a rotation and a translation block quarters the
  // cells of the reduced camera system that the Schur elimination fills (and locks one by one).
  // The manifold, the shared robust kernel and the poses are declared before the problem,
  // which points into them and so must go first.
  PoseManifold pose_manifold;
  ceres::HuberLoss huber(o.huber_px);
  std::vector<std::array<double, 7>> poses(pb.poses.size());
  for (size_t i = 0; i < pb.poses.size(); ++i) {
    std::copy_n(pb.poses[i].q_cw.coeffs().data(), 4, poses[i].data());
    std::copy_n(pb.poses[i].t_cw.data(), 3, poses[i].data() + 4);
  }
  ceres::Problem::Options problem_options;
  problem_options.manifold_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  problem_options.loss_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  ceres::Problem problem(problem_options);
  std::vector<ceres::ResidualBlockId> blocks;  // null: left out
  const double bound = std::sqrt(5.991);
  for (const auto& ob : pb.observations) {
    auto& point = pb.points[static_cast<size_t>(ob.point)];
    // A point beside or behind the camera (over 84 degrees off its axis) cannot be what the
    // keypoint saw, and near the camera plane the projection's derivatives blow up: one such
    // observation (a point 0.009 behind a new keyframe) outweighed 4,900 others, dragged the
    // keyframe 0.29 map units off and left it with one point. It goes out as an outlier
    // (levelError is infinite there).
    if (const double e = levelError(pb, ob); !std::isfinite(e) || (o.outliers == Outliers::FromStart && e > bound)) {
      blocks.push_back(nullptr);
      continue;
    }
    auto* cost = new ReprojectionError(pb.K, ob.uv, ob.inv_sigma);
    blocks.push_back(problem.AddResidualBlock(cost, &huber,
                                              poses[static_cast<size_t>(ob.pose)].data(), point.p_w.data()));
  }
  for (size_t i = 0; i < poses.size(); ++i) {
    if (!problem.HasParameterBlock(poses[i].data())) continue;
    problem.SetManifold(poses[i].data(), &pose_manifold);
    if (pb.poses[i].fixed) problem.SetParameterBlockConstant(poses[i].data());
  }
  // The solution back into the problem's poses (the outlier judgement reads them).
  auto copyBack = [&]() {
    for (size_t i = 0; i < poses.size(); ++i) {
      std::copy_n(poses[i].data(), 4, pb.poses[i].q_cw.coeffs().data());
      std::copy_n(poses[i].data() + 4, 3, pb.poses[i].t_cw.data());
    }
  };
  for (auto& point : pb.points)
    if (point.fixed && problem.HasParameterBlock(point.p_w.data())) problem.SetParameterBlockConstant(point.p_w.data());

  ceres::Solver::Options options;
  options.linear_solver_type = pb.poses.size() <= static_cast<size_t>(o.dense_schur_max_poses) ? ceres::DENSE_SCHUR
                                                                                               : ceres::SPARSE_SCHUR;
  options.max_num_iterations = o.iterations;
  options.num_threads = 1;
  options.logging_type = ceres::SILENT;
  AbortCallback abort(o.abort);
  options.callbacks.push_back(&abort);
  ceres::Solver::Summary summary;
  if (problem.NumResidualBlocks() > 0) ceres::Solve(options, &problem, &summary);
  copyBack();

  BaSummary out;
  out.initial_cost = summary.initial_cost;
  out.iterations = static_cast<int>(summary.iterations.size());
  auto classify = [&]() {
    out.outlier.assign(pb.observations.size(), false);
    for (size_t i = 0; i < pb.observations.size(); ++i) out.outlier[i] = levelError(pb, pb.observations[i]) > bound;
  };
  classify();
  // Second round without the outliers: even under a robust kernel they pull the solution.
  const bool aborted = o.abort && o.abort->load();
  out.aborted = aborted;
  int removed = 0;
  for (size_t i = 0; i < blocks.size() && !aborted && o.outliers == Outliers::SecondRound; ++i)
    if (out.outlier[i] && blocks[i] && problem.NumResidualBlocks() > 1) {
      problem.RemoveResidualBlock(blocks[i]);
      ++removed;
    }
  if (removed > 0) {
    options.max_num_iterations = std::max(o.iterations / 2, 5);
    ceres::Solve(options, &problem, &summary);
    copyBack();
    out.iterations += static_cast<int>(summary.iterations.size());
    classify();
  }
  out.converged = summary.termination_type == ceres::CONVERGENCE;
  out.final_cost = summary.final_cost;
  return out;
}

double medianResidualSigma(const BaProblem& pb) {
  std::vector<double> r;
  r.reserve(pb.observations.size());
  for (const auto& ob : pb.observations)
    if (const double e = levelError(pb, ob); std::isfinite(e)) r.push_back(e);
  if (r.empty()) return 0.0;
  auto mid = r.begin() + static_cast<std::ptrdiff_t>(r.size() / 2);
  std::nth_element(r.begin(), mid, r.end());
  return *mid / std::sqrt(2.0 * std::log(2.0));
}

void setNoise(BaProblem& pb, double sigma) {
  for (auto& ob : pb.observations) ob.inv_sigma /= sigma;
}

double setNoiseFromResiduals(BaProblem& pb, double factor) {
  const double sigma = std::clamp(factor * medianResidualSigma(pb), 0.1, 1.0);
  setNoise(pb, sigma);
  return sigma;
}

double solveGlobal(BaProblem& pb, int iterations, double noise_factor, Outliers outliers, bool loose_first) {
  BaOptions o;
  o.iterations = iterations;
  o.outliers = Outliers::Kept;
  if (loose_first) bundleAdjust(pb, o);
  double sigma = 0;
  if (noise_factor > 0) {
    sigma = setNoiseFromResiduals(pb, noise_factor);
    o.outliers = outliers;
  }
  bundleAdjust(pb, o);
  return sigma;
}

}  // namespace hiveslam::core
