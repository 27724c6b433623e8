#include "eval/scale_precision.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <random>

#include "common/error.hpp"
#include "eval/similarity.hpp"

namespace hiveslam::eval {

namespace {

Eigen::Vector2d project(const core::BaProblem& b, const core::BaObservation& ob) {
  const core::BaPose& pose = b.poses[static_cast<size_t>(ob.pose)];
  const Eigen::Vector3d pc = pose.q_cw * b.points[static_cast<size_t>(ob.point)].p_w + pose.t_cw;
  return {b.K.fx * pc.x() / pc.z() + b.K.cx, b.K.fy * pc.y() / pc.z() + b.K.cy};
}

// Keyframe centres of one stretch.
Eigen::Matrix3Xd centres(const core::BaProblem& b, const std::vector<size_t>& which) {
  Eigen::Matrix3Xd c(3, static_cast<Eigen::Index>(which.size()));
  for (size_t i = 0; i < which.size(); ++i) {
    const core::BaPose& p = b.poses[which[i]];
    c.col(static_cast<Eigen::Index>(i)) = -(p.q_cw.conjugate() * p.t_cw);
  }
  return c;
}

}  // namespace

double residualNoise(const core::BaProblem& problem) {
  double sum = 0.0;
  size_t used = 0;
  for (const auto& ob : problem.observations) {
    const double r2 = (project(problem, ob) - ob.uv).squaredNorm() * ob.inv_sigma * ob.inv_sigma;
    if (r2 > 5.991) continue;
    sum += r2;
    ++used;
  }
  size_t free_poses = 0;
  for (const auto& p : problem.poses) free_poses += !p.fixed;
  const double dof = 2.0 * static_cast<double>(used) - 3.0 * static_cast<double>(problem.points.size()) -
                     6.0 * static_cast<double>(free_poses);
  return dof > 0 ? std::sqrt(sum / dof) : 0.0;
}

ScalePrecision computeScalePrecision(const core::BaProblem& problem, const std::vector<double>& stamps,
                                     const ScalePrecisionOptions& options) {
  ScalePrecision out;
  out.keyframes = problem.poses.size();
  out.points = problem.points.size();
  out.observations = problem.observations.size();
  if (stamps.size() != problem.poses.size()) throw InputError("one time stamp per keyframe is needed");
  std::vector<size_t> first, second;
  const double t0 = stamps.empty() ? 0.0 : *std::min_element(stamps.begin(), stamps.end());
  for (size_t i = 0; i < stamps.size(); ++i) {
    if (options.split.inFirst(stamps[i] - t0)) first.push_back(i);
    if (options.split.inSecond(stamps[i] - t0)) second.push_back(i);
  }
  out.first_keyframes = first.size();
  out.second_keyframes = second.size();
  if (first.size() < 3 || second.size() < 3)
    throw InputError(fmt::format("the stretches have {} and {} keyframes; 3 each needed", first.size(), second.size()));
  out.residual_noise = residualNoise(problem);
  out.noise = options.noise > 0 ? options.noise : out.residual_noise;

  // The map's solution with measurements that fit it exactly; observations the map itself
  // holds as outliers stay out.
  core::BaProblem clean = problem;
  clean.observations.clear();
  for (const auto& ob : problem.observations) {
    const Eigen::Vector2d exact = project(problem, ob);
    if ((exact - ob.uv).squaredNorm() * ob.inv_sigma * ob.inv_sigma > 5.991) continue;
    clean.observations.push_back(ob);
    clean.observations.back().uv = exact;
  }
  const Eigen::Matrix3Xd first_clean = centres(clean, first), second_clean = centres(clean, second);

  std::mt19937_64 rng(options.seed);
  std::normal_distribution<double> normal(0.0, 1.0);
  core::BaOptions ba;
  ba.iterations = options.iterations;
  ba.outliers = core::Outliers::Kept;
  for (int t = 0; t < options.trials; ++t) {
    core::BaProblem noisy = clean;
    for (auto& ob : noisy.observations) ob.uv += Eigen::Vector2d(normal(rng), normal(rng)) * (out.noise / ob.inv_sigma);
    core::bundleAdjust(noisy, ba);
    // Each stretch aligned onto its clean self: its re-solved size relative to the clean one.
    const double s1 = 1.0 / umeyama(centres(noisy, first), first_clean, true).scale;
    const double s2 = 1.0 / umeyama(centres(noisy, second), second_clean, true).scale;
    out.steps.push_back(s2 / s1);
  }
  if (!out.steps.empty()) {
    double sum = 0.0, sum2 = 0.0;
    for (double s : out.steps) sum += s;
    out.mean = sum / static_cast<double>(out.steps.size());
    for (double s : out.steps) sum2 += (s - out.mean) * (s - out.mean);
    out.sd = out.steps.size() > 1 ? std::sqrt(sum2 / static_cast<double>(out.steps.size() - 1)) : 0.0;
  }
  return out;
}

}  // namespace hiveslam::eval
