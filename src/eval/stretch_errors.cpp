#include "eval/stretch_errors.hpp"

#include "common/error.hpp"

namespace hiveslam::eval {

std::vector<Stretch> stretchErrors(const AteResult& ate, int stretches) {
  if (stretches < 1) throw InputError("the run must be cut into at least 1 stretch");
  const io::Trajectory& ref = ate.pair.ref;
  const double t0 = ref.stamps.front(), span = ref.stamps.back() - t0;
  std::vector<Stretch> out(static_cast<size_t>(stretches));
  std::vector<std::vector<size_t>> members(out.size());
  for (size_t k = 0; k < out.size(); ++k) {
    out[k].from = span * static_cast<double>(k) / stretches;
    out[k].to = span * static_cast<double>(k + 1) / stretches;
  }
  for (size_t i = 0; i < ref.size(); ++i) {
    const double t = ref.stamps[i] - t0;
    const size_t k = span > 0 ? std::min(out.size() - 1, static_cast<size_t>(t / span * stretches)) : 0;
    members[k].push_back(i);
  }
  // The aligned estimate is the raw one under a similarity: a stretch's own Sim3 from the
  // aligned poses is the raw one's composed with the whole-run alignment, so its scale is
  // multiplied by the whole run's.
  for (size_t k = 0; k < out.size(); ++k) {
    const auto& m = members[k];
    out[k].poses = m.size();
    if (m.empty()) continue;
    double sum = 0;
    Eigen::Matrix3Xd from(3, m.size()), to(3, m.size());
    for (size_t j = 0; j < m.size(); ++j) {
      sum += ate.errors[m[j]];
      from.col(static_cast<Eigen::Index>(j)) = ate.pair.est.poses[m[j]].translation();
      to.col(static_cast<Eigen::Index>(j)) = ref.poses[m[j]].translation();
    }
    out[k].mean_error = sum / static_cast<double>(m.size());
    if (m.size() >= 3) out[k].scale = umeyama(from, to, true).scale * ate.pair.alignment.scale;
    const Eigen::Matrix3d ref_turn = ref.poses[m.front()].linear().transpose() * ref.poses[m.back()].linear();
    const Eigen::Matrix3d est_turn =
        ate.pair.est.poses[m.front()].linear().transpose() * ate.pair.est.poses[m.back()].linear();
    out[k].turn = rotationDegrees(ref_turn);
    out[k].turn_estimate = rotationDegrees(est_turn);
    out[k].turn_error = rotationDegrees(ref_turn.transpose() * est_turn);
  }
  return out;
}

}  // namespace hiveslam::eval
