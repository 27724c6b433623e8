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
  MatchOptions paired = match;
  paired.alignment = Alignment::None;  // each stretch is aligned on its own below
  const AlignedPair pair = matchAndAlign(ref, est, paired);
  const double t0 = pair.est.stamps.front();
  std::vector<Eigen::Vector3d> est1, ref1, est2, ref2;
  for (size_t i = 0; i < pair.est.size(); ++i) {
    const double t = pair.est.stamps[i] - t0;
    const Eigen::Vector3d pe = pair.est.poses[i].translation(), pr = pair.ref.poses[i].translation();
    if (split.inFirst(t)) {
      est1.push_back(pe);
      ref1.push_back(pr);
    } else if (split.inSecond(t)) {
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
