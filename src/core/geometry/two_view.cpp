#include "core/geometry/two_view.hpp"

#include <algorithm>
#include <cmath>
#include <opencv2/calib3d.hpp>
#include <opencv2/core/eigen.hpp>

namespace hiveslam::core {

namespace {

constexpr double kChi2_2dof = 5.991;  // 95% for a 2D point error
constexpr double kChi2_1dof = 3.841;  // 95% for a distance to a line

// Symmetric transfer score of a homography (ORB-SLAM's model selection score).
double scoreHomography(const Eigen::Matrix3d& H, const std::vector<Eigen::Vector2d>& p1,
                       const std::vector<Eigen::Vector2d>& p2, double sigma) {
  const Eigen::Matrix3d Hinv = H.inverse();
  const double inv_s2 = 1.0 / (sigma * sigma);
  double score = 0;
  for (size_t i = 0; i < p1.size(); ++i) {
    const Eigen::Vector3d a = H * p1[i].homogeneous(), b = Hinv * p2[i].homogeneous();
    const double chi21 = (a.hnormalized() - p2[i]).squaredNorm() * inv_s2;
    const double chi12 = (b.hnormalized() - p1[i]).squaredNorm() * inv_s2;
    if (chi21 < kChi2_2dof) score += kChi2_2dof - chi21;
    if (chi12 < kChi2_2dof) score += kChi2_2dof - chi12;
  }
  return score;
}

double scoreFundamental(const Eigen::Matrix3d& F, const std::vector<Eigen::Vector2d>& p1,
                        const std::vector<Eigen::Vector2d>& p2, double sigma) {
  const double inv_s2 = 1.0 / (sigma * sigma);
  double score = 0;
  for (size_t i = 0; i < p1.size(); ++i) {
    const Eigen::Vector3d l2 = F * p1[i].homogeneous(), l1 = F.transpose() * p2[i].homogeneous();
    const double d2 = p2[i].homogeneous().dot(l2), d1 = p1[i].homogeneous().dot(l1);
    const double chi2 = d2 * d2 / l2.head<2>().squaredNorm() * inv_s2;
    const double chi1 = d1 * d1 / l1.head<2>().squaredNorm() * inv_s2;
    if (chi2 < kChi2_1dof) score += kChi2_2dof - chi2;
    if (chi1 < kChi2_1dof) score += kChi2_2dof - chi1;
  }
  return score;
}

struct Candidate {
  Eigen::Isometry3d T_21;
  std::vector<Eigen::Vector3d> points;
  std::vector<bool> good;
  int count = 0;      // matches triangulated with parallax, in front of both views
  int explained = 0;  // those, plus matches too close to parallel to say where they are
  double median_parallax_deg = 0;
};

// A match the motion explains without placing it: its rays meet within the reprojection
// threshold but at too little parallax to tell the side of the cameras (or at infinity).
bool explainedWithoutParallax(const Eigen::Vector3d& r1, const Eigen::Vector3d& r2, const Eigen::Isometry3d& T_21,
                              double f, const TriangulationCheck& check) {
  const auto X = intersectRays(r1, r2, T_21);
  if (!X) return f * (T_21.linear() * r1).normalized().cross(r2.normalized()).norm() <= check.max_reprojection_px;
  const Eigen::Vector3d p2 = T_21 * *X;
  const Eigen::Vector3d c2_in_1 = T_21.inverse().translation();
  const double cos_parallax = std::abs(X->normalized().dot((*X - c2_in_1).normalized()));
  if (cos_parallax <= check.min_parallax_cos) return false;
  return f * (X->head<2>() / X->z() - r1.head<2>()).norm() <= check.max_reprojection_px &&
         f * (p2.head<2>() / p2.z() - r2.head<2>()).norm() <= check.max_reprojection_px;
}

Candidate reconstruct(const Eigen::Matrix3d& R, const Eigen::Vector3d& t, const std::vector<Eigen::Vector2d>& p1,
                      const std::vector<Eigen::Vector2d>& p2, const Intrinsics& K, const TwoViewOptions& o) {
  Candidate c;
  c.T_21 = Eigen::Isometry3d::Identity();
  c.T_21.linear() = R;
  c.T_21.translation() = t.normalized();
  c.points.assign(p1.size(), Eigen::Vector3d::Zero());
  c.good.assign(p1.size(), false);
  std::vector<double> parallax;
  // Reprojection check in pixels of the sigma-scaled 2-dof threshold.
  TriangulationCheck check = o.check;
  check.max_reprojection_px = std::max(check.max_reprojection_px, 0.0);
  const double f = 0.5 * (K.fx + K.fy);
  for (size_t i = 0; i < p1.size(); ++i) {
    double cos_parallax = 1.0;
    const auto X = triangulate(K.ray(p1[i]), K.ray(p2[i]), c.T_21, f, check, &cos_parallax);
    if (!X) {
      c.explained += explainedWithoutParallax(K.ray(p1[i]), K.ray(p2[i]), c.T_21, f, check);
      continue;
    }
    c.points[i] = *X;
    c.good[i] = true;
    ++c.count;
    ++c.explained;
    parallax.push_back(std::acos(std::clamp(cos_parallax, -1.0, 1.0)) * 180.0 / M_PI);
  }
  if (!parallax.empty()) {
    std::nth_element(parallax.begin(), parallax.begin() + parallax.size() / 2, parallax.end());
    c.median_parallax_deg = parallax[parallax.size() / 2];
  }
  return c;
}

}  // namespace

TwoViewResult initializeTwoView(const std::vector<Eigen::Vector2d>& p1, const std::vector<Eigen::Vector2d>& p2,
                                const Intrinsics& K, const TwoViewOptions& o) {
  TwoViewResult r;
  if (p1.size() < static_cast<size_t>(std::max(o.min_points, 8))) {
    r.reason = "too few matches";
    return r;
  }
  std::vector<cv::Point2d> a, b;
  for (size_t i = 0; i < p1.size(); ++i) {
    a.emplace_back(p1[i].x(), p1[i].y());
    b.emplace_back(p2[i].x(), p2[i].y());
  }
  const cv::Matx33d Kcv(K.fx, 0, K.cx, 0, K.fy, K.cy, 0, 0, 1);
  // OpenCV's RANSAC draws from the calling thread's RNG: seed it for repeatable maps.
  cv::setRNGSeed(static_cast<int>(o.seed & 0x7fffffff));
  const cv::Mat Hcv = cv::findHomography(a, b, cv::RANSAC, 2.0 * o.sigma_px * std::sqrt(kChi2_2dof), cv::noArray(),
                                         o.homography_iterations, 0.999);
  cv::setRNGSeed(static_cast<int>((o.seed + 1) & 0x7fffffff));
  const cv::Mat Ecv = cv::findEssentialMat(a, b, Kcv, cv::RANSAC, 0.999, o.sigma_px * std::sqrt(kChi2_1dof),
                                           o.essential_iterations);
  if (Ecv.rows != 3 || Ecv.cols != 3) {
    r.reason = "no essential matrix";
    return r;
  }
  Eigen::Matrix3d H = Eigen::Matrix3d::Identity(), E, Km;
  if (!Hcv.empty()) cv::cv2eigen(Hcv, H);
  cv::cv2eigen(Ecv, E);
  cv::cv2eigen(cv::Mat(Kcv), Km);
  const Eigen::Matrix3d F = Km.inverse().transpose() * E * Km.inverse();
  const double sh = Hcv.empty() ? 0.0 : scoreHomography(H, p1, p2, o.sigma_px);
  const double sf = scoreFundamental(F, p1, p2, o.sigma_px);
  const bool use_h = sh + sf > 0 && sh / (sh + sf) > o.homography_ratio;

  std::vector<Candidate> candidates;
  if (use_h) {
    r.model = "homography";
    std::vector<cv::Mat> Rs, ts, ns;
    cv::decomposeHomographyMat(Hcv, Kcv, Rs, ts, ns);
    for (size_t i = 0; i < Rs.size(); ++i) {
      Eigen::Matrix3d R;
      Eigen::Vector3d t;
      cv::cv2eigen(Rs[i], R);
      cv::cv2eigen(ts[i], t);
      if (t.norm() < 1e-9) continue;
      candidates.push_back(reconstruct(R, t, p1, p2, K, o));
    }
  } else {
    r.model = "essential";
    // All four (R, t) of the essential matrix; the cheirality count picks one.
    cv::Mat R1, R2, t;
    cv::decomposeEssentialMat(Ecv, R1, R2, t);
    for (const cv::Mat& Rc : {R1, R2})
      for (double sign : {1.0, -1.0}) {
        Eigen::Matrix3d R;
        Eigen::Vector3d tv;
        cv::cv2eigen(Rc, R);
        cv::cv2eigen(cv::Mat(t * sign), tv);
        candidates.push_back(reconstruct(R, tv, p1, p2, K, o));
      }
  }
  if (candidates.empty()) {
    r.reason = "no motion hypothesis";
    return r;
  }
  std::sort(candidates.begin(), candidates.end(), [](const Candidate& x, const Candidate& y) { return x.count > y.count; });
  const Candidate& best = candidates.front();
  if (best.count < o.min_points) {
    r.reason = "too few triangulated points";
    return r;
  }
  if (candidates.size() > 1 && candidates[1].count > 0.75 * best.count) {
    r.reason = "ambiguous motion";
    return r;
  }
  // The motion that triangulates the most points must also explain the most matches. On a thin
  // baseline a wrong rotation wins the count: its error shows up as parallax, so it
  // "triangulates" nearly every match, while the true motion leaves most of them too parallel to
  // place (KITTI 07, frames 0-1: a homography solution 1.3 degrees off placed 93% of the matches
  // at 1.3 degrees of parallax, and two other decompositions explained more of the matches).
  for (const Candidate& c : candidates)
    if (c.explained > best.explained) {
      r.reason = "parallax from a rotation error";
      return r;
    }
  if (best.median_parallax_deg < o.min_parallax_deg) {
    r.reason = "too little parallax";
    return r;
  }
  r.ok = true;
  r.T_21 = best.T_21;
  r.points = best.points;
  r.good = best.good;
  r.good_count = best.count;
  r.median_parallax_deg = best.median_parallax_deg;
  return r;
}

}  // namespace hiveslam::core
