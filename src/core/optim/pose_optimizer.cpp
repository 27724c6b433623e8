#include "core/optim/pose_optimizer.hpp"

#include "core/geometry/skew.hpp"

#include <Eigen/Cholesky>
#include <cmath>
#include <limits>

namespace hiveslam::core {

namespace {

constexpr double kChi2 = 5.991;  // 95% of chi-square with 2 degrees of freedom
constexpr int kRounds = 4;
constexpr int kIterations = 10;

// exp of an se(3) twist (rotation first, then translation), enough for small steps.
Eigen::Isometry3d expSE3(const Eigen::Matrix<double, 6, 1>& d) {
  const Eigen::Vector3d w = d.head<3>();
  const Eigen::Vector3d rho = d.tail<3>();
  const double theta = w.norm();
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  const Eigen::Matrix3d W = skew(w);
  Eigen::Matrix3d V = Eigen::Matrix3d::Identity();
  if (theta < 1e-10) {
    T.linear() = Eigen::Matrix3d::Identity() + W;
    V += 0.5 * W;
  } else {
    T.linear() = Eigen::AngleAxisd(theta, w / theta).toRotationMatrix();
    const double t2 = theta * theta;
    V += (1 - std::cos(theta)) / t2 * W + (theta - std::sin(theta)) / (t2 * theta) * W * W;
  }
  T.translation() = V * rho;
  return T;
}

double chi2Of(const Intrinsics& K, const PoseObservation& o, const Eigen::Isometry3d& T) {
  const Eigen::Vector3d pc = T * o.point;
  if (pc.z() <= 0) return 1e9;
  return ((K.project(pc) - o.uv) * o.inv_sigma).squaredNorm();
}

// One Gauss-Newton (IRLS) solve over the observations not flagged as outliers. With `robust`,
// large residuals are down-weighted by `loss`, as Ceres' HuberLoss or CauchyLoss would.
void solve(const Intrinsics& K, const std::vector<PoseObservation>& obs, const std::vector<bool>& outlier,
           const PoseLoss* robust, Eigen::Isometry3d& T) {
  double last_cost = std::numeric_limits<double>::infinity();
  Eigen::Isometry3d last_T = T;
  for (int it = 0; it < kIterations; ++it) {
    Eigen::Matrix<double, 6, 6> H = Eigen::Matrix<double, 6, 6>::Zero();
    Eigen::Matrix<double, 6, 1> b = Eigen::Matrix<double, 6, 1>::Zero();
    double cost = 0;
    for (size_t i = 0; i < obs.size(); ++i) {
      if (outlier[i]) continue;
      const Eigen::Vector3d pc = T * obs[i].point;
      if (pc.z() <= 1e-6) continue;
      const double iz = 1.0 / pc.z();
      const Eigen::Vector2d r = (K.project(pc) - obs[i].uv) * obs[i].inv_sigma;
      const double e = r.norm();
      double w = 1.0;
      if (!robust) {
        cost += e * e;
      } else if (const double c = robust->scale; robust->kind == PoseLoss::Kind::Huber) {
        w = e > c ? c / e : 1.0;
        cost += e > c ? 2 * c * e - c * c : e * e;
      } else {
        const double u = e * e / (c * c);
        w = 1.0 / (1.0 + u);
        cost += c * c * std::log1p(u);
      }
      Eigen::Matrix<double, 2, 3> Jp;
      Jp << K.fx * iz, 0, -K.fx * pc.x() * iz * iz, 0, K.fy * iz, -K.fy * pc.y() * iz * iz;
      Jp *= obs[i].inv_sigma;
      // Left perturbation T <- exp(d) T: d(pc)/d(w, rho) = [-[pc]x, I].
      Eigen::Matrix<double, 2, 6> J;
      J.leftCols<3>() = -Jp * skew(pc);
      J.rightCols<3>() = Jp;
      H.noalias() += w * J.transpose() * J;
      b.noalias() += w * J.transpose() * r;
    }
    // A step that raised the cost is undone, and the solve ends there.
    if (cost > last_cost) {
      T = last_T;
      return;
    }
    const Eigen::Matrix<double, 6, 1> d = H.ldlt().solve(-b);
    if (!d.allFinite()) return;
    last_cost = cost;
    last_T = T;
    T = expSE3(d) * T;
    if (d.squaredNorm() < 1e-12) break;
  }
}

}  // namespace

int optimizePose(const Intrinsics& K, const std::vector<PoseObservation>& obs, Eigen::Isometry3d& T_cw,
                 std::vector<bool>& outlier, const PoseLoss& loss) {
  outlier.assign(obs.size(), false);
  if (obs.size() < 3) return 0;
  int inliers = 0;
  for (int round = 0; round < kRounds; ++round) {
    // The last round runs without the robust kernel, on inliers only.
    const Eigen::Isometry3d before = T_cw;
    solve(K, obs, outlier, round < kRounds - 1 ? &loss : nullptr, T_cw);
    inliers = 0;
    for (size_t i = 0; i < obs.size(); ++i) {
      // Every round re-classifies all observations: an early outlier may come back.
      outlier[i] = chi2Of(K, obs[i], T_cw) > kChi2;
      if (!outlier[i]) ++inliers;
    }
    if (inliers < 10) {
      if (round == kRounds - 1) T_cw = before;
      break;
    }
  }
  T_cw.linear() = Eigen::Quaterniond(T_cw.linear()).normalized().toRotationMatrix();
  return inliers;
}

}  // namespace hiveslam::core
