#include "eval/association.hpp"

#include <algorithm>
#include <cmath>
#include <fmt/format.h>

#include "common/error.hpp"

namespace hiveslam::eval {

namespace {

// Index of the stamp nearest to t, the first one on a tie (numpy argmin's rule).
size_t nearest(const std::vector<double>& stamps, bool sorted, double t) {
  if (!sorted) {
    size_t best = 0;
    for (size_t i = 1; i < stamps.size(); ++i)
      if (std::abs(stamps[i] - t) < std::abs(stamps[best] - t)) best = i;
    return best;
  }
  const auto it = std::lower_bound(stamps.begin(), stamps.end(), t);
  size_t hi = static_cast<size_t>(it - stamps.begin());
  if (hi == stamps.size()) return stamps.size() - 1;
  if (hi == 0) return 0;
  // Equal stamps can repeat: step back to the first of a run of equal values.
  size_t lo = hi - 1;
  while (lo > 0 && stamps[lo - 1] == stamps[lo]) --lo;
  return std::abs(stamps[lo] - t) <= std::abs(stamps[hi] - t) ? lo : hi;
}

}  // namespace

Association associateByTime(const io::Trajectory& ref, const io::Trajectory& est, double max_diff) {
  Association a;
  if (ref.empty() || est.empty()) return a;
  const bool est_is_short = est.size() <= ref.size();
  const auto& shorter = est_is_short ? est.stamps : ref.stamps;
  const auto& longer = est_is_short ? ref.stamps : est.stamps;
  const bool sorted = std::is_sorted(longer.begin(), longer.end());
  for (size_t i = 0; i < shorter.size(); ++i) {
    const size_t j = nearest(longer, sorted, shorter[i]);
    if (std::abs(longer[j] - shorter[i]) <= max_diff) {
      a.est.push_back(est_is_short ? i : j);
      a.ref.push_back(est_is_short ? j : i);
    }
  }
  return a;
}

Association associateByIndex(const io::Trajectory& ref, const io::Trajectory& est) {
  if (ref.size() != est.size())
    throw InputError(fmt::format("trajectories paired by line need as many poses ({} vs {})",
                                 ref.size(), est.size()));
  Association a;
  for (size_t i = 0; i < ref.size(); ++i) {
    a.ref.push_back(i);
    a.est.push_back(i);
  }
  return a;
}

}  // namespace hiveslam::eval
