#include "eval/trajectory_error.hpp"

#include <cmath>
#include <fmt/format.h>

#include "common/error.hpp"

namespace hiveslam::eval {

std::string toString(Alignment a) {
  switch (a) {
    case Alignment::None: return "none";
    case Alignment::SE3: return "se3";
    case Alignment::Sim3: return "sim3";
  }
  return "?";
}

double rotationDegrees(const Eigen::Matrix3d& R) { return Eigen::AngleAxisd(R).angle() * 180.0 / M_PI; }

AlignedPair matchAndAlign(const io::Trajectory& ref, const io::Trajectory& est,
                          const MatchOptions& options) {
  const Association a =
      options.by_index ? associateByIndex(ref, est) : associateByTime(ref, est, options.max_diff);
  if (a.size() < 3)
    throw InputError(fmt::format(
        "only {} poses matched in time (max difference {} s): are the stamps in the same clock?",
        a.size(), options.max_diff));
  AlignedPair p;
  Eigen::Matrix3Xd from(3, a.size()), to(3, a.size());
  for (size_t i = 0; i < a.size(); ++i) {
    p.ref.add(ref.stamps[a.ref[i]], ref.poses[a.ref[i]]);
    p.est.add(est.stamps[a.est[i]], est.poses[a.est[i]]);
    from.col(i) = p.est.poses[i].translation();
    to.col(i) = p.ref.poses[i].translation();
  }
  if (options.alignment != Alignment::None) {
    p.alignment = umeyama(from, to, options.alignment == Alignment::Sim3);
    for (auto& T : p.est.poses) T = p.alignment.apply(T);
  }
  return p;
}

AteResult computeAte(const io::Trajectory& ref, const io::Trajectory& est,
                     const MatchOptions& options) {
  AteResult r;
  r.pair = matchAndAlign(ref, est, options);
  for (size_t i = 0; i < r.pair.ref.size(); ++i)
    r.errors.push_back((r.pair.est.poses[i].translation() - r.pair.ref.poses[i].translation()).norm());
  r.stats = summarize(r.errors);
  r.reference_length = r.pair.ref.pathLength();
  return r;
}

namespace {

// evo's filters.filter_pairs_by_index / filter_pairs_by_path.
std::vector<std::pair<size_t, size_t>> rpePairs(const io::Trajectory& ref, const RpeOptions& o) {
  std::vector<std::pair<size_t, size_t>> pairs;
  const size_t n = ref.size();
  if (o.unit == DeltaUnit::Frames) {
    const size_t d = static_cast<size_t>(o.delta);
    if (d < 1) throw InputError("RPE delta in frames must be at least 1");
    if (o.all_pairs) {
      for (size_t i = 0; i + d < n; ++i) pairs.emplace_back(i, i + d);
    } else {
      for (size_t i = 0; i + d < n; i += d) pairs.emplace_back(i, i + d);
    }
    return pairs;
  }
  // Distance in metres along the reference path.
  std::vector<double> along(n, 0.0);
  for (size_t i = 1; i < n; ++i)
    along[i] = along[i - 1] + (ref.poses[i].translation() - ref.poses[i - 1].translation()).norm();
  if (o.all_pairs) {
    const double tol = 0.01 * o.delta;
    for (size_t i = 0; i < n; ++i)
      for (size_t j = i + 1; j < n; ++j)
        if (std::abs(along[j] - along[i] - o.delta) <= tol) {
          pairs.emplace_back(i, j);
          break;
        }
    return pairs;
  }
  size_t last = 0;
  double travelled = 0.0;
  for (size_t i = 1; i < n; ++i) {
    travelled += along[i] - along[i - 1];
    if (travelled >= o.delta) {
      pairs.emplace_back(last, i);
      last = i;
      travelled = 0.0;
    }
  }
  return pairs;
}

}  // namespace

RpeResult computeRpe(const io::Trajectory& ref, const io::Trajectory& est, const RpeOptions& o) {
  const AlignedPair p = matchAndAlign(ref, est, o.match);
  RpeResult r;
  r.pairs = rpePairs(p.ref, o);
  for (auto [i, j] : r.pairs) {
    const Eigen::Isometry3d d_ref = p.ref.poses[i].inverse() * p.ref.poses[j];
    const Eigen::Isometry3d d_est = p.est.poses[i].inverse() * p.est.poses[j];
    const Eigen::Isometry3d E = d_ref.inverse() * d_est;
    if (o.relation == RpeRelation::Translation) {
      r.errors.push_back(E.translation().norm());
    } else {
      r.errors.push_back(rotationDegrees(E.linear()));
    }
  }
  if (r.errors.empty()) throw InputError("no RPE pairs for this delta: the trajectory is too short");
  r.stats = summarize(r.errors);
  return r;
}

}  // namespace hiveslam::eval
