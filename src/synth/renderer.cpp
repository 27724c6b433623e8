#include "synth/renderer.hpp"

#include <cmath>

namespace hiveslam::synth {

void renderRadiance(const Scene& scene, const RayTable& rays, const Eigen::Isometry3d& T_wc,
                    cv::Mat& radiance, cv::Mat* depth) {
  renderRadiance(scene, rays, std::vector<Eigen::Isometry3d>{T_wc}, radiance, depth);
}

void renderRadiance(const Scene& scene, const RayTable& rays, const std::vector<Eigen::Isometry3d>& T_wc_rows,
                    cv::Mat& radiance, cv::Mat* depth) {
  radiance.create(rays.height, rays.width, CV_32F);
  if (depth) depth->create(rays.height, rays.width, CV_32F);
  for (int v = 0; v < rays.height; ++v) {
    const Eigen::Isometry3d& T_wc = T_wc_rows[T_wc_rows.size() == 1 ? 0 : static_cast<size_t>(v)];
    const Eigen::Matrix3d R = T_wc.linear();
    const Eigen::Vector3d origin = T_wc.translation();
    float* out = radiance.ptr<float>(v);
    float* dout = depth ? depth->ptr<float>(v) : nullptr;
    for (int u = 0; u < rays.width; ++u) {
      const size_t i = static_cast<size_t>(v) * rays.width + u;
      // The ray keeps z = 1 in the camera frame, so the hit parameter t is the depth.
      const Eigen::Vector3d d = R * rays.rays[i];
      const auto hit = scene.intersect(origin, d);
      if (!hit) {
        out[u] = 0.0f;
        if (dout) dout[u] = 0.0f;
        continue;
      }
      const double len = d.norm();
      const double cos_incidence = std::max(std::abs(d.dot(hit->normal)) / len, 0.02);
      // Footprint of the pixel on the surface: `minor` across the view direction, stretched
      // by 1 / cos(incidence) along the surface direction the ray leans towards.
      const double minor = hit->t * rays.pixel_size[i];
      const double major = minor / cos_incidence;
      double du = d.dot(hit->axis_u), dv = d.dot(hit->axis_v);
      const double dn = std::hypot(du, dv);
      if (dn > 1e-9) {
        du /= dn;
        dv /= dn;
      } else {
        du = 1.0;
        dv = 0.0;
      }
      const float albedo = scene.textures[static_cast<size_t>(hit->texture)].sample(
          hit->u, hit->v, minor, major, du, dv);
      const double shade = scene.shading(origin + hit->t * d, hit->normal);
      out[u] = static_cast<float>(albedo * shade);
      if (dout) dout[u] = static_cast<float>(hit->t);
    }
  }
}

}  // namespace hiveslam::synth
