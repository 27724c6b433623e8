// The analytic reprojection residual and its pose manifold: what Ceres computes from them (the
// cost's Jacobian times the manifold's PlusJacobian) must be the derivative of the residual
// along the manifold's own steps, and equal to what automatic differentiation through the
// product manifold they replace gave.
#include <gtest/gtest.h>

#include <ceres/autodiff_cost_function.h>
#include <ceres/product_manifold.h>
#include <ceres/rotation.h>

#include <Eigen/Geometry>
#include <random>

#include "core/optim/reprojection_error.hpp"

namespace hiveslam::core {
namespace {

// The residual as it was differentiated before: by dual numbers, in the 7 stored numbers.
struct AutoDiffReprojection {
  Intrinsics K;
  Eigen::Vector2d uv;
  double w;
  template <typename T>
  bool operator()(const T* pose, const T* p, T* r) const {
    const T qw[4] = {pose[3], pose[0], pose[1], pose[2]};
    T pc[3];
    ceres::QuaternionRotatePoint(qw, p, pc);
    for (int i = 0; i < 3; ++i) pc[i] += pose[4 + i];
    if (pc[2] <= T(1e-6)) pc[2] = T(1e-6);
    r[0] = (T(K.fx) * pc[0] / pc[2] + T(K.cx) - T(uv.x())) * T(w);
    r[1] = (T(K.fy) * pc[1] / pc[2] + T(K.cy) - T(uv.y())) * T(w);
    return true;
  }
};

using Matrix26 = Eigen::Matrix<double, 2, 6, Eigen::RowMajor>;
using Matrix27 = Eigen::Matrix<double, 2, 7, Eigen::RowMajor>;
using Matrix23 = Eigen::Matrix<double, 2, 3, Eigen::RowMajor>;

struct Case {
  std::array<double, 7> pose;
  Eigen::Vector3d point;
  Eigen::Vector2d uv;
  double w;
};

Case randomCase(std::mt19937& rng, double depth) {
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  Case c;
  const Eigen::Quaterniond q = Eigen::Quaterniond(Eigen::Vector4d(u(rng), u(rng), u(rng), u(rng)).normalized());
  const Eigen::Vector3d t(u(rng), u(rng), u(rng));
  std::copy_n(q.coeffs().data(), 4, c.pose.data());
  std::copy_n(t.data(), 3, c.pose.data() + 4);
  // A point at the given depth in front of the camera, a little off its axis.
  const Eigen::Vector3d pc(0.4 * u(rng) * depth, 0.3 * u(rng) * depth, depth);
  c.point = q.conjugate() * (pc - t);
  c.uv = Eigen::Vector2d(320 + 40 * u(rng), 240 + 40 * u(rng));
  c.w = 1.0 / (1.0 + 0.5 * (u(rng) + 1.0));
  return c;
}

const Intrinsics kK{458.0, 457.0, 367.0, 248.0};

// The derivative along the manifold's steps, by central differences.
Matrix26 numericTangentJacobian(const ReprojectionError& cost, const Case& c) {
  const PoseManifold manifold;
  Matrix26 J;
  const double h = 1e-6;
  for (int k = 0; k < 6; ++k) {
    double d[6] = {0, 0, 0, 0, 0, 0}, plus[7], minus[7];
    d[k] = h;
    manifold.Plus(c.pose.data(), d, plus);
    d[k] = -h;
    manifold.Plus(c.pose.data(), d, minus);
    double rp[2], rm[2];
    const double* pp[2] = {plus, c.point.data()};
    const double* pm[2] = {minus, c.point.data()};
    cost.Evaluate(pp, rp, nullptr);
    cost.Evaluate(pm, rm, nullptr);
    for (int r = 0; r < 2; ++r) J(r, k) = (rp[r] - rm[r]) / (2 * h);
  }
  return J;
}

TEST(ReprojectionError, PoseJacobianTimesPlusJacobianIsTheDerivativeAlongTheSteps) {
  std::mt19937 rng(7);
  const PoseManifold manifold;
  for (int trial = 0; trial < 50; ++trial) {
    const Case c = randomCase(rng, 0.5 + 0.2 * trial);
    const ReprojectionError cost(kK, c.uv, c.w);
    const double* params[2] = {c.pose.data(), c.point.data()};
    double r[2];
    Matrix27 J_pose;
    Matrix23 J_point;
    double* jac[2] = {J_pose.data(), J_point.data()};
    ASSERT_TRUE(cost.Evaluate(params, r, jac));
    Eigen::Matrix<double, 7, 6, Eigen::RowMajor> plus;
    manifold.PlusJacobian(c.pose.data(), plus.data());
    const Matrix26 tangent = J_pose * plus;
    const Matrix26 numeric = numericTangentJacobian(cost, c);
    EXPECT_LT((tangent - numeric).norm(), 1e-5 * (1.0 + numeric.norm())) << "trial " << trial << "\n" << tangent << "\n" << numeric;
  }
}

// The analytic residual and the automatically differentiated one, at the same parameters.
struct Evaluated {
  Eigen::Vector2d r, r_ref;
  Matrix27 J_pose, J_pose_ref;
  Matrix23 J_point, J_point_ref;
};
Evaluated evaluateBoth(const Case& c) {
  const ReprojectionError cost(kK, c.uv, c.w);
  const ceres::AutoDiffCostFunction<AutoDiffReprojection, 2, 7, 3> reference(new AutoDiffReprojection{kK, c.uv, c.w});
  const double* params[2] = {c.pose.data(), c.point.data()};
  Evaluated e;
  double* jac[2] = {e.J_pose.data(), e.J_point.data()};
  double* jac_ref[2] = {e.J_pose_ref.data(), e.J_point_ref.data()};
  EXPECT_TRUE(cost.Evaluate(params, e.r.data(), jac));
  EXPECT_TRUE(reference.Evaluate(params, e.r_ref.data(), jac_ref));
  return e;
}

TEST(ReprojectionError, MatchesAutomaticDifferentiationThroughTheProductManifold) {
  std::mt19937 rng(11);
  const ceres::ProductManifold<ceres::EigenQuaternionManifold, ceres::EuclideanManifold<3>> product;
  const PoseManifold manifold;
  for (int trial = 0; trial < 50; ++trial) {
    const Case c = randomCase(rng, 0.3 + 0.3 * trial);
    const Evaluated e = evaluateBoth(c);
    const auto& [r, r_ref, J_pose, J_pose_ref, J_point, J_point_ref] = e;
    EXPECT_NEAR(r[0], r_ref[0], 1e-9 * (1 + std::abs(r_ref[0])));
    EXPECT_NEAR(r[1], r_ref[1], 1e-9 * (1 + std::abs(r_ref[1])));
    Eigen::Matrix<double, 7, 6, Eigen::RowMajor> plus, plus_ref;
    manifold.PlusJacobian(c.pose.data(), plus.data());
    product.PlusJacobian(c.pose.data(), plus_ref.data());
    const Matrix26 tangent = J_pose * plus, tangent_ref = J_pose_ref * plus_ref;
    EXPECT_LT((tangent - tangent_ref).norm(), 1e-9 * (1.0 + tangent_ref.norm())) << "trial " << trial;
    EXPECT_LT((J_point - J_point_ref).norm(), 1e-9 * (1.0 + J_point_ref.norm())) << "trial " << trial;

    // The same steps: Plus and Minus agree with the product manifold's.
    const double delta[6] = {0.01 * trial, -0.02, 0.005, 0.1, -0.2, 0.3};
    double a[7], b[7], back[6], back_ref[6];
    manifold.Plus(c.pose.data(), delta, a);
    product.Plus(c.pose.data(), delta, b);
    for (int i = 0; i < 7; ++i) EXPECT_NEAR(a[i], b[i], 1e-12);
    manifold.Minus(a, c.pose.data(), back);
    product.Minus(a, c.pose.data(), back_ref);
    for (int i = 0; i < 6; ++i) {
      EXPECT_NEAR(back[i], delta[i], 1e-9);
      EXPECT_NEAR(back[i], back_ref[i], 1e-9);
    }
  }
}

TEST(ReprojectionError, BehindTheCameraTheResidualStaysFiniteAndTheDepthIsConstant) {
  std::mt19937 rng(3);
  Case c = randomCase(rng, 2.0);
  // Move the point behind the camera.
  Eigen::Map<const Eigen::Quaterniond> q(c.pose.data());
  const Eigen::Vector3d t(c.pose[4], c.pose[5], c.pose[6]);
  const Eigen::Vector3d pc = q * c.point + t;
  c.point = q.conjugate() * (Eigen::Vector3d(pc.x(), pc.y(), -1.0) - t);
  const Evaluated e = evaluateBoth(c);
  const auto& [r, r_ref, J_pose, J_pose_ref, J_point, J_point_ref] = e;
  EXPECT_TRUE(std::isfinite(r[0]) && std::isfinite(r[1]));
  EXPECT_NEAR(r[0], r_ref[0], 1e-6 * std::abs(r_ref[0]));
  EXPECT_NEAR(r[1], r_ref[1], 1e-6 * std::abs(r_ref[1]));
  EXPECT_LT((J_point - J_point_ref).norm(), 1e-6 * J_point_ref.norm());
}

}  // namespace
}  // namespace hiveslam::core
