#include "core/optim/sim3_refine.hpp"

#include <ceres/ceres.h>
#include <ceres/rotation.h>

namespace hiveslam::core {

namespace {

struct Sim3ReprojectionError {
  Sim3ReprojectionError(const Intrinsics& K1, const Intrinsics& K2, const Sim3Match& m) : K1(K1), K2(K2), m(m) {}

  template <typename T>
  bool operator()(const T* q, const T* t, const T* log_s, T* r) const {
    const Eigen::Map<const Eigen::Quaternion<T>> Q(q);
    const Eigen::Map<const Eigen::Matrix<T, 3, 1>> tv(t);
    const T s = ceres::exp(log_s[0]);
    const Eigen::Matrix<T, 3, 1> in1 = s * (Q * m.p2.cast<T>()) + tv;
    const Eigen::Matrix<T, 3, 1> in2 = Q.conjugate() * (m.p1.cast<T>() - tv) / s;
    const T w1 = T(1.0 / std::sqrt(m.sigma2_1)), w2 = T(1.0 / std::sqrt(m.sigma2_2));
    r[0] = (T(K1.fx) * in1.x() / in1.z() + T(K1.cx) - T(m.uv1.x())) * w1;
    r[1] = (T(K1.fy) * in1.y() / in1.z() + T(K1.cy) - T(m.uv1.y())) * w1;
    r[2] = (T(K2.fx) * in2.x() / in2.z() + T(K2.cx) - T(m.uv2.x())) * w2;
    r[3] = (T(K2.fy) * in2.y() / in2.z() + T(K2.cy) - T(m.uv2.y())) * w2;
    return true;
  }
  Intrinsics K1, K2;
  Sim3Match m;
};

}  // namespace

int refineSim3(const Intrinsics& K1, const Intrinsics& K2, const std::vector<Sim3Match>& matches, Sim3& S12,
               std::vector<bool>& inlier, bool fixed_scale, double chi2) {
  inlier.resize(matches.size(), true);
  Eigen::Quaterniond q = S12.q;
  Eigen::Vector3d t = S12.t;
  double log_s = std::log(S12.s);
  int count = 0;
  for (int round = 0; round < 2; ++round) {
    ceres::Problem problem;
    int used = 0;
    for (size_t i = 0; i < matches.size(); ++i) {
      if (!inlier[i]) continue;
      problem.AddResidualBlock(
          new ceres::AutoDiffCostFunction<Sim3ReprojectionError, 4, 4, 3, 1>(new Sim3ReprojectionError(K1, K2, matches[i])),
          new ceres::HuberLoss(std::sqrt(chi2)), q.coeffs().data(), t.data(), &log_s);
      ++used;
    }
    if (used < 3) return 0;
    problem.SetManifold(q.coeffs().data(), new ceres::EigenQuaternionManifold);
    if (fixed_scale) problem.SetParameterBlockConstant(&log_s);
    ceres::Solver::Options options;
    options.linear_solver_type = ceres::DENSE_QR;
    options.max_num_iterations = round == 0 ? 10 : 5;
    options.logging_type = ceres::SILENT;
    ceres::Solver::Summary summary;
    ceres::Solve(options, &problem, &summary);
    const Sim3 S(q, t, std::exp(log_s));
    count = 0;
    for (size_t i = 0; i < matches.size(); ++i) {
      inlier[i] = inlier[i] && sim3Inlier(K1, K2, matches[i], S, chi2);
      count += inlier[i];
    }
  }
  S12 = Sim3(q, t, std::exp(log_s));
  return count;
}

}  // namespace hiveslam::core
