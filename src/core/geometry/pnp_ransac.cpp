#include "core/geometry/pnp_ransac.hpp"

#include <opencv2/calib3d.hpp>

namespace hiveslam::core {

std::optional<PnpResult> solvePnpRansac(const Intrinsics& K, const std::vector<PnpMatch>& matches, double threshold_px,
                                        int min_inliers, int seed) {
  if (matches.size() < 4 || static_cast<int>(matches.size()) < min_inliers) return std::nullopt;
  std::vector<cv::Point3d> object;
  std::vector<cv::Point2d> image;
  object.reserve(matches.size());
  image.reserve(matches.size());
  for (const auto& m : matches) {
    object.emplace_back(m.p_w.x(), m.p_w.y(), m.p_w.z());
    image.emplace_back(m.uv.x(), m.uv.y());
  }
  cv::UsacParams usac;
  usac.threshold = threshold_px;
  usac.confidence = 0.99;
  usac.maxIterations = 300;
  usac.loMethod = cv::LOCAL_OPTIM_NULL;  // the caller refines the pose on the inliers
  usac.isParallel = false;
  usac.randomGeneratorState = seed;
  const cv::Matx33d Kcv(K.fx, 0, K.cx, 0, K.fy, K.cy, 0, 0, 1);
  cv::Mat rvec, tvec, inliers;
  try {
    if (!cv::solvePnPRansac(object, image, Kcv, cv::noArray(), rvec, tvec, inliers, usac)) return std::nullopt;
  } catch (const cv::Exception&) {
    return std::nullopt;  // degenerate samples only (e.g. every point on one line)
  }
  if (static_cast<int>(inliers.total()) < min_inliers) return std::nullopt;
  cv::Mat R;
  cv::Rodrigues(rvec, R);
  PnpResult r;
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) r.T_cw.linear()(i, j) = R.at<double>(i, j);
    r.T_cw.translation()(i) = tvec.at<double>(i);
  }
  r.inliers.assign(inliers.begin<int>(), inliers.end<int>());
  return r;
}

}  // namespace hiveslam::core
