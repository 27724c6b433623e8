#include "core/optim/pose_graph.hpp"

#include <ceres/ceres.h>

namespace hiveslam::core {

namespace {

// Residual of E = S_ij^-1 * S_iw * S_jw^-1: rotation (twice the quaternion's vector part),
// translation and log scale, all zero when the poses agree with the measurement.
struct Sim3EdgeError {
  Sim3EdgeError(const Sim3& m, double w) : inv(m.inverse()), w(w) {}

  template <typename T>
  bool operator()(const T* qi, const T* ti, const T* si, const T* qj, const T* tj, const T* sj, T* r) const {
    using Q = Eigen::Quaternion<T>;
    using V = Eigen::Matrix<T, 3, 1>;
    const Eigen::Map<const Q> Qi(qi), Qj(qj);
    const Eigen::Map<const V> Ti(ti), Tj(tj);
    const T Si = ceres::exp(si[0]), Sj = ceres::exp(sj[0]);
    // S_jw^-1 = (Qj^-1, -Qj^-1 tj / sj, 1/sj)
    const Q qji = Qj.conjugate();
    const V tji = -(qji * Tj) / Sj;
    // A = S_iw * S_jw^-1
    const Q qa = Qi * qji;
    const V ta = Si * (Qi * tji) + Ti;
    const T sa = Si / Sj;
    // E = inv * A
    const Q qm = inv.q.cast<T>();
    const Q qe = qm * qa;
    const V te = T(inv.s) * (qm * ta) + inv.t.cast<T>();
    const T se = T(inv.s) * sa;
    const T sign = qe.w() < T(0) ? T(-1) : T(1);
    r[0] = T(2) * sign * qe.x() * T(w);
    r[1] = T(2) * sign * qe.y() * T(w);
    r[2] = T(2) * sign * qe.z() * T(w);
    r[3] = te.x() * T(w);
    r[4] = te.y() * T(w);
    r[5] = te.z() * T(w);
    r[6] = ceres::log(se) * T(w);
    return true;
  }
  Sim3 inv;
  double w;
};

}  // namespace

PoseGraphSummary optimizePoseGraph(PoseGraph& graph, int iterations) {
  const size_t n = graph.poses.size();
  std::vector<Eigen::Quaterniond> q(n);
  std::vector<Eigen::Vector3d> t(n);
  std::vector<double> log_s(n);
  for (size_t i = 0; i < n; ++i) {
    q[i] = graph.poses[i].q.normalized();
    t[i] = graph.poses[i].t;
    log_s[i] = std::log(graph.poses[i].s);
  }
  ceres::Problem problem;
  for (const PoseGraphEdge& e : graph.edges) {
    const auto i = static_cast<size_t>(e.i), j = static_cast<size_t>(e.j);
    problem.AddResidualBlock(new ceres::AutoDiffCostFunction<Sim3EdgeError, 7, 4, 3, 1, 4, 3, 1>(
                                 new Sim3EdgeError(e.S_ij, e.weight)),
                             nullptr, q[i].coeffs().data(), t[i].data(), &log_s[i], q[j].coeffs().data(),
                             t[j].data(), &log_s[j]);
  }
  PoseGraphSummary out;
  for (size_t i = 0; i < n; ++i) {
    if (!problem.HasParameterBlock(t[i].data())) continue;
    problem.SetManifold(q[i].coeffs().data(), new ceres::EigenQuaternionManifold);
    if (graph.fixed[i]) {
      problem.SetParameterBlockConstant(q[i].coeffs().data());
      problem.SetParameterBlockConstant(t[i].data());
      problem.SetParameterBlockConstant(&log_s[i]);
    }
  }
  if (graph.edges.empty()) return out;
  ceres::Solver::Options options;
  options.linear_solver_type = ceres::SPARSE_NORMAL_CHOLESKY;
  options.sparse_linear_algebra_library_type = ceres::EIGEN_SPARSE;
  options.max_num_iterations = iterations;
  options.num_threads = 1;
  options.logging_type = ceres::SILENT;
  ceres::Solver::Summary summary;
  ceres::Solve(options, &problem, &summary);
  out.initial_cost = summary.initial_cost;
  out.final_cost = summary.final_cost;
  out.iterations = static_cast<int>(summary.iterations.size());
  for (size_t i = 0; i < n; ++i) graph.poses[i] = Sim3(q[i], t[i], std::exp(log_s[i]));
  return out;
}

}  // namespace hiveslam::core
