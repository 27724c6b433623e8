#pragma once
// Bundle adjustment over keyframe poses (T_cw) and points (world), on the undistorted ideal
// pinhole image, with a Huber kernel and per-observation weights from the pyramid level. The
// same problem serves the initial full BA, local BA (border keyframes fixed) and global BA.
#include <Eigen/Geometry>
#include <atomic>
#include <vector>

#include "core/frame/frame.hpp"

namespace hiveslam::core {

struct BaPose {
  Eigen::Quaterniond q_cw = Eigen::Quaterniond::Identity();
  Eigen::Vector3d t_cw = Eigen::Vector3d::Zero();
  bool fixed = false;

  Eigen::Isometry3d T_cw() const {
    Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
    T.linear() = q_cw.normalized().toRotationMatrix();
    T.translation() = t_cw;
    return T;
  }
};

struct BaPoint {
  Eigen::Vector3d p_w = Eigen::Vector3d::Zero();
  bool fixed = false;
};

struct BaObservation {
  int pose = 0;
  int point = 0;
  Eigen::Vector2d uv;       // undistorted pixel
  double inv_sigma = 1.0;   // 1 / (scale of the keypoint's pyramid level)
};

struct BaProblem {
  Intrinsics K;
  std::vector<BaPose> poses;
  std::vector<BaPoint> points;
  std::vector<BaObservation> observations;
};

// What happens to observations beyond the chi-square bound (5.991, 2 dof).
enum class Outliers {
  Kept,         // one round; the Huber kernel alone bounds their pull
  SecondRound,  // optimize again without the observations the first round rejects
  // Judged on the starting residuals and left out of the one round. For a start that is near
  // its optimum already (a map no correction has moved), where the start tells the outliers as
  // well as a first round would, at a third of the time.
  FromStart,
};

struct BaOptions {
  int iterations = 20;
  double huber_px = 2.447;                 // sqrt(5.991): the 95% chi-square bound, 2 dof
  const std::atomic<bool>* abort = nullptr;  // checked between iterations (a new keyframe came)
  Outliers outliers = Outliers::SecondRound;
  // Problems with at most this many poses factor the reduced camera system densely, bigger ones
  // sparsely (SuiteSparse); dense also keeps CHOLMOD out of the small local windows. In the global
  // BAs of rendered maps (91 and 140 keyframes) dense solves the linear systems 25-40% faster
  // and the whole BA 17-26%; on core_bench's BundleAdjust (a corridor, sparser) dense is 8%
  // faster at 150 poses and sparse 10% faster at 200.
  int dense_schur_max_poses = 150;
};

struct BaSummary {
  bool converged = false;
  bool aborted = false;  // cut short by BaOptions::abort
  int iterations = 0;
  double initial_cost = 0, final_cost = 0;
  std::vector<bool> outlier;  // per observation: chi-square above 5.991 after optimizing
};

BaSummary bundleAdjust(BaProblem& problem, const BaOptions& options = {});

// The observations' noise per coordinate, in units of their level sigmas, read off the median
// reprojection error as a 2D Gaussian's (the median of its norm is sqrt(2 ln 2) = 1.1774
// sigmas), so the few observations far off do not inflate it. 0 without observations.
double medianResidualSigma(const BaProblem& problem);

// Expresses every observation's weight in units of `sigma` level sigmas (sigma < 1: the
// measurements are more precise than one pixel per level), so that the Huber kernel and the
// chi-square test of the outlier round judge residuals against the noise the map really has.
void setNoise(BaProblem& problem, double sigma);
// setNoise with `factor` times the noise medianResidualSigma reads, clamped to 0.1-1 px per level
// (a tenth of a pixel at the least: a map fitted exactly, a test's noiseless one, would otherwise
// call every rounding error an outlier). Returns the sigma set.
double setNoiseFromResiduals(BaProblem& problem, double factor);

// A global BA's solve. With `loose_first`, one solve at a pixel per level with nothing left out
// goes first: observations measured again start far from the map's solution, and judged at once
// against the tight noise, those that would pull the map into its new shape look like outliers
// and sit out. Then, with noise_factor > 0, the noise is set
// from the residuals (setNoiseFromResiduals) and `outliers` applies; without it, one solve with
// every observation kept. Returns the sigma set (0 when none).
double solveGlobal(BaProblem& problem, int iterations, double noise_factor, Outliers outliers, bool loose_first);

}  // namespace hiveslam::core
