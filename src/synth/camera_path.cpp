#include "synth/camera_path.hpp"

#include <algorithm>
#include <cmath>
#include <random>

namespace hiveslam::synth {

Spline::Spline(std::vector<Eigen::Vector3d> points) : points_(std::move(points)) {}

Eigen::Vector3d Spline::at(double u) const {
  const int n = static_cast<int>(points_.size());
  if (n == 1) return points_[0];
  u = std::clamp(u, 0.0, maxParam());
  const int i = std::min(static_cast<int>(u), n - 2);
  const double f = u - i;
  // Ends are extended by reflection so that the curve passes through every waypoint.
  auto P = [&](int k) -> Eigen::Vector3d {
    if (k < 0) return 2 * points_[0] - points_[1];
    if (k >= n) return 2 * points_[n - 1] - points_[n - 2];
    return points_[k];
  };
  const Eigen::Vector3d p0 = P(i - 1), p1 = P(i), p2 = P(i + 1), p3 = P(i + 2);
  // Centripetal parameterization (alpha = 0.5) avoids cusps and self-intersections.
  auto knot = [](const Eigen::Vector3d& a, const Eigen::Vector3d& b, double t) {
    return t + std::max(std::sqrt((b - a).norm()), 1e-6);
  };
  const double t0 = 0, t1 = knot(p0, p1, t0), t2 = knot(p1, p2, t1), t3 = knot(p2, p3, t2);
  const double t = t1 + f * (t2 - t1);
  const Eigen::Vector3d a1 = (t1 - t) / (t1 - t0) * p0 + (t - t0) / (t1 - t0) * p1;
  const Eigen::Vector3d a2 = (t2 - t) / (t2 - t1) * p1 + (t - t1) / (t2 - t1) * p2;
  const Eigen::Vector3d a3 = (t3 - t) / (t3 - t2) * p2 + (t - t2) / (t3 - t2) * p3;
  const Eigen::Vector3d b1 = (t2 - t) / (t2 - t0) * a1 + (t - t0) / (t2 - t0) * a2;
  const Eigen::Vector3d b2 = (t3 - t) / (t3 - t1) * a2 + (t - t1) / (t3 - t1) * a3;
  return (t2 - t) / (t2 - t1) * b1 + (t - t1) / (t2 - t1) * b2;
}

CameraPath::CameraPath(const std::vector<Waypoint>& waypoints, double duration, double wobble,
                       unsigned seed)
    : duration_(duration), wobble_(wobble) {
  std::vector<Eigen::Vector3d> eyes, targets;
  for (const auto& w : waypoints) {
    eyes.push_back(w.eye);
    targets.push_back(w.target);
    pace_.push_back(w.pace);
  }
  eye_ = Spline(eyes);
  target_ = Spline(targets);
  const int steps = static_cast<int>(waypoints.size()) * 200;
  Eigen::Vector3d prev = eye_.at(0);
  table_u_.push_back(0);
  table_s_.push_back(0);
  table_e_.push_back(0);
  for (int k = 1; k <= steps; ++k) {
    const double u = eye_.maxParam() * k / steps;
    const Eigen::Vector3d p = eye_.at(u);
    const double step = (p - prev).norm();
    const size_t segment = std::min(static_cast<size_t>(std::max(u - 1e-9, 0.0)), pace_.size() - 1);
    length_ += step;
    effort_ += step / std::max(pace_[segment], 1e-3);
    prev = p;
    table_u_.push_back(u);
    table_s_.push_back(length_);
    table_e_.push_back(effort_);
  }
  std::mt19937 rng(seed);
  for (double& p : phase_) p = std::uniform_real_distribution<double>(0, 2 * M_PI)(rng);
  for (double& p : tremor_phase_) p = std::uniform_real_distribution<double>(0, 2 * M_PI)(rng);
}

namespace {

// Linear interpolation of ys at x in the increasing table xs.
double lookup(const std::vector<double>& xs, const std::vector<double>& ys, double x) {
  const auto it = std::lower_bound(xs.begin(), xs.end(), x);
  if (it == xs.begin()) return ys.front();
  if (it == xs.end()) return ys.back();
  const size_t i = static_cast<size_t>(it - xs.begin());
  const double f = (x - xs[i - 1]) / std::max(xs[i] - xs[i - 1], 1e-12);
  return ys[i - 1] + f * (ys[i] - ys[i - 1]);
}

}  // namespace

double CameraPath::paramAtDistance(double s) const { return lookup(table_s_, table_u_, s); }

double CameraPath::paramAtEffort(double e) const { return lookup(table_e_, table_u_, e); }

double CameraPath::effortAtTime(double t) const {
  // Trapezoidal speed with cosine ramps over the first and last 8% of the duration.
  const double T = duration_, r = 0.08 * T;
  const double L = effort_;
  const double v = L / (T - r);  // cruise speed: the ramps together cover r * v
  t = std::clamp(t, 0.0, T);
  auto ramp = [&](double x) {  // distance covered after x seconds of a ramp from rest
    return v * (x / 2 - r / (2 * M_PI) * std::sin(M_PI * x / r));
  };
  if (t < r) return ramp(t);
  if (t > T - r) return L - ramp(T - t);
  return ramp(r) + v * (t - r);
}

Eigen::Isometry3d CameraPath::pose(double t) const {
  const double u = paramAt(t);
  const Eigen::Vector3d eye = eye_.at(u);
  const Eigen::Vector3d target = target_.at(u);
  const Eigen::Vector3d z = (target - eye).normalized();
  Eigen::Vector3d x = z.cross(Eigen::Vector3d::UnitZ());
  if (x.norm() < 1e-6) x = Eigen::Vector3d::UnitX();  // looking straight up or down
  x.normalize();
  const Eigen::Vector3d y = z.cross(x);
  Eigen::Matrix3d R;
  R << x, y, z;
  // Hand-held wobble: two incommensurate sines per axis, at most `wobble` radians.
  const double roll = wobble_ * 0.5 * (std::sin(0.9 * t + phase_[0]) + std::sin(2.3 * t + phase_[1]));
  const double pitch = wobble_ * 0.5 * (std::sin(0.7 * t + phase_[2]) + std::sin(1.9 * t + phase_[3]));
  R = R * Eigen::AngleAxisd(roll, Eigen::Vector3d::UnitZ()).toRotationMatrix() *
      Eigen::AngleAxisd(pitch, Eigen::Vector3d::UnitX()).toRotationMatrix();
  Eigen::Vector3d shake = Eigen::Vector3d::Zero(), turn = Eigen::Vector3d::Zero();
  if (tremor_rad_ > 0 || tremor_m_ > 0) {
    // Per axis, three sines at 1.3-4.9 Hz whose amplitudes sum to the tremor's.
    static constexpr double kHz[3][3] = {{1.3, 2.9, 4.7}, {1.7, 3.1, 4.9}, {1.1, 2.3, 4.1}};
    for (int a = 0; a < 3; ++a)
      for (int k = 0; k < 3; ++k) {
        const double w = std::sin(2 * M_PI * kHz[a][k] * t + tremor_phase_[3 * a + k]) / 3.0;
        turn[a] += tremor_rad_ * w;
        shake[a] += tremor_m_ * std::sin(2 * M_PI * kHz[2 - a][k] * 0.7 * t + tremor_phase_[(3 * a + k + 4) % 12]) / 3.0;
      }
  }
  if (turn.norm() > 0) R = R * Eigen::AngleAxisd(turn.norm(), turn.normalized()).toRotationMatrix();
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = R;
  T.translation() = eye + shake;
  return T;
}

std::vector<Eigen::Vector3d> CameraPath::samples(double spacing) const {
  std::vector<Eigen::Vector3d> out;
  for (double s = 0; s <= length_; s += spacing) out.push_back(eye_.at(paramAtDistance(s)));
  out.push_back(eye_.at(eye_.maxParam()));
  return out;
}

}  // namespace hiveslam::synth
