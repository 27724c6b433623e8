#include "core/geometry/sim3_solver.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <random>

namespace hiveslam::core {

namespace {

Sim3 closedForm(const std::vector<Sim3Match>& matches, const std::vector<size_t>& which, bool fixed_scale) {
  Eigen::Matrix3Xd src(3, which.size()), dst(3, which.size());
  for (size_t i = 0; i < which.size(); ++i) {
    src.col(static_cast<Eigen::Index>(i)) = matches[which[i]].p2;
    dst.col(static_cast<Eigen::Index>(i)) = matches[which[i]].p1;
  }
  const Eigen::Matrix4d T = Eigen::umeyama(src, dst, !fixed_scale);
  const Eigen::Matrix3d sR = T.topLeftCorner<3, 3>();
  const double s = std::cbrt(sR.determinant());
  return Sim3(Eigen::Quaterniond(sR / s), T.topRightCorner<3, 1>(), s);
}

}  // namespace

bool sim3Inlier(const Intrinsics& K1, const Intrinsics& K2, const Sim3Match& m, const Sim3& S12, double chi2) {
  const Eigen::Vector3d in1 = S12 * m.p2;
  const Eigen::Vector3d in2 = S12.inverse() * m.p1;
  if (in1.z() <= 0 || in2.z() <= 0) return false;
  return (K1.project(in1) - m.uv1).squaredNorm() <= chi2 * m.sigma2_1 &&
         (K2.project(in2) - m.uv2).squaredNorm() <= chi2 * m.sigma2_2;
}

Sim3Result solveSim3Ransac(const Intrinsics& K1, const Intrinsics& K2, const std::vector<Sim3Match>& matches,
                           const Sim3RansacOptions& options) {
  Sim3Result best;
  const size_t n = matches.size();
  if (n < 3 || static_cast<int>(n) < options.min_inliers) return best;
  std::mt19937_64 rng(options.seed);
  std::uniform_int_distribution<size_t> pick(0, n - 1);
  std::vector<bool> inlier(n);
  for (int it = 0; it < options.iterations; ++it) {
    std::vector<size_t> sample;
    while (sample.size() < 3) {
      const size_t k = pick(rng);
      if (std::find(sample.begin(), sample.end(), k) == sample.end()) sample.push_back(k);
    }
    const Sim3 S = closedForm(matches, sample, options.fixed_scale);
    if (!(S.s > 0) || !S.t.allFinite()) continue;
    int count = 0;
    for (size_t i = 0; i < n; ++i) {
      inlier[i] = sim3Inlier(K1, K2, matches[i], S, options.chi2);
      count += inlier[i];
    }
    if (count > best.inliers) {
      best.inliers = count;
      best.inlier = inlier;
      best.S12 = S;
      if (count > 0.9 * static_cast<double>(n)) break;
    }
  }
  if (best.inliers < options.min_inliers) return Sim3Result{};
  // Re-estimate on every inlier, keep it if it does not lose inliers.
  std::vector<size_t> all;
  for (size_t i = 0; i < n; ++i)
    if (best.inlier[i]) all.push_back(i);
  const Sim3 S = closedForm(matches, all, options.fixed_scale);
  int count = 0;
  for (size_t i = 0; i < n; ++i) {
    inlier[i] = sim3Inlier(K1, K2, matches[i], S, options.chi2);
    count += inlier[i];
  }
  if (count >= best.inliers) {
    best.S12 = S;
    best.inlier = inlier;
    best.inliers = count;
  }
  best.found = true;
  return best;
}

namespace {

std::vector<double> depthRatios(const std::vector<Sim3Match>& matches, const Sim3& S12, const std::vector<bool>& inlier) {
  std::vector<double> ratios;
  for (size_t k = 0; k < matches.size() && k < inlier.size(); ++k) {
    if (!inlier[k]) continue;
    const Eigen::Vector3d q = S12.q * matches[k].p2;
    if (q.squaredNorm() > 1e-12) ratios.push_back((matches[k].p1 - S12.t).dot(q) / q.squaredNorm());
  }
  return ratios;
}

}  // namespace

double pointScaleAgreement(const std::vector<Sim3Match>& matches, const Sim3& S12, const std::vector<bool>& inlier,
                           double tolerance) {
  const std::vector<double> ratios = depthRatios(matches, S12, inlier);
  if (ratios.empty()) return 0;
  const auto near = std::count_if(ratios.begin(), ratios.end(),
                                  [&](double r) { return std::abs(r / S12.s - 1.0) <= tolerance; });
  return static_cast<double>(near) / static_cast<double>(ratios.size());
}

double pointScale(const std::vector<Sim3Match>& matches, const Sim3& S12, const std::vector<bool>& inlier) {
  std::vector<double> ratios = depthRatios(matches, S12, inlier);
  if (ratios.empty()) return S12.s;
  auto mid = ratios.begin() + static_cast<std::ptrdiff_t>(ratios.size() / 2);
  std::nth_element(ratios.begin(), mid, ratios.end());
  return *mid;
}

}  // namespace hiveslam::core
