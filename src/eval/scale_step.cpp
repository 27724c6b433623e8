#include "eval/scale_step.hpp"

#include <fmt/format.h>

#include "common/error.hpp"

namespace hiveslam::eval {

namespace {

double stretchScale(const std::vector<Eigen::Vector3d>& est, const std::vector<Eigen::Vector3d>& ref,
                    const char* which) {
  if (est.size() < 3) throw InputError(fmt::format("the {} stretch has {} matched poses; 3 needed", which, est.size()));
  Eigen::Matrix3Xd from(3, est.size()), to(3, ref.size());
  for (size_t i = 0; i < est.size(); ++i) {
    from.col(static_cast<Eigen::Index>(i)) = est[i];
    to.col(static_cast<Eigen::Index>(i)) = ref[i];
  }
  return 1.0 / umeyama(from, to, true).scale;
}

}  // namespace

ScaleStep computeScaleStep(const io::Trajectory& ref, const io::Trajectory& est, const StretchSplit& split,
                           const MatchOptions& match) {
  const Association a = match.by_index ? associateByIndex(ref, est) : associateByTime(ref, est, match.max_diff);
  if (a.size() == 0) throw InputError("no poses of the estimate match the reference");
  const double t0 = est.stamps[a.est.front()];
  std::vector<Eigen::Vector3d> est1, ref1, est2, ref2;
  for (size_t i = 0; i < a.size(); ++i) {
    const double t = est.stamps[a.est[i]] - t0;
    const Eigen::Vector3d pe = est.poses[a.est[i]].translation(), pr = ref.poses[a.ref[i]].translation();
    if (t <= split.before) {
      est1.push_back(pe);
      ref1.push_back(pr);
    } else if (t >= split.after) {
      est2.push_back(pe);
      ref2.push_back(pr);
    }
  }
  ScaleStep s;
  s.first_scale = stretchScale(est1, ref1, "first");
  s.second_scale = stretchScale(est2, ref2, "second");
  s.first_poses = est1.size();
  s.second_poses = est2.size();
  return s;
}

}  // namespace hiveslam::eval
