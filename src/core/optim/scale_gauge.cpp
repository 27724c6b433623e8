#include "core/optim/scale_gauge.hpp"

namespace hiveslam::core {

std::vector<Eigen::Vector3d> cameraCentres(const BaProblem& problem) {
  std::vector<Eigen::Vector3d> centres;
  centres.reserve(problem.poses.size());
  for (const auto& p : problem.poses) centres.push_back(-(p.q_cw.conjugate() * p.t_cw));
  return centres;
}

double restoreScale(BaProblem& problem, const std::vector<Eigen::Vector3d>& centres_before) {
  if (centres_before.size() != problem.poses.size()) return 1.0;
  size_t anchor = problem.poses.size(), fixed = 0;
  for (size_t i = 0; i < problem.poses.size(); ++i)
    if (problem.poses[i].fixed && fixed++ == 0) anchor = i;
  if (fixed != 1) return 1.0;  // none: no centre to scale about; two or more hold the scale already
  const std::vector<Eigen::Vector3d> after = cameraCentres(problem);
  const Eigen::Vector3d o = after[anchor];
  double spread_before = 0, spread_after = 0;
  for (size_t i = 0; i < after.size(); ++i) {
    spread_before += (centres_before[i] - centres_before[anchor]).norm();
    spread_after += (after[i] - o).norm();
  }
  // Cameras that (nearly) share the fixed one's centre give no scale to restore.
  constexpr double kNoSpread = 1e-12;
  if (spread_before <= kNoSpread || spread_after <= kNoSpread) return 1.0;
  const double s = spread_before / spread_after;
  // x -> o + s (x - o): a camera keeps its rotation; its centre moves, so t = -R c follows.
  for (size_t i = 0; i < problem.poses.size(); ++i) {
    auto& p = problem.poses[i];
    if (p.fixed) continue;
    const Eigen::Vector3d c = o + s * (after[i] - o);
    p.t_cw = -(p.q_cw * c);
  }
  for (auto& p : problem.points)
    if (!p.fixed) p.p_w = o + s * (p.p_w - o);
  return s;
}

}  // namespace hiveslam::core
