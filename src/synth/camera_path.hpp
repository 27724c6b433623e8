#pragma once
// A smooth camera motion: a centripetal Catmull-Rom spline through eye waypoints, a second one
// through look-at targets, travelled at a speed profile that starts and ends at rest, plus a
// small deterministic hand-held wobble in roll and pitch.
#include <Eigen/Geometry>
#include <cmath>
#include <vector>

namespace hiveslam::synth {

class Spline {
 public:
  Spline() = default;
  explicit Spline(std::vector<Eigen::Vector3d> points);
  // Position at parameter u in [0, points-1].
  Eigen::Vector3d at(double u) const;
  double maxParam() const { return static_cast<double>(points_.size()) - 1.0; }

 private:
  std::vector<Eigen::Vector3d> points_;
};

struct Waypoint {
  Eigen::Vector3d eye;
  Eigen::Vector3d target;
  double pace = 1.0;  // speed on the segment to the next waypoint, relative to the cruise speed
};

class CameraPath {
 public:
  // duration: seconds from the first to the last waypoint; wobble: roll/pitch amplitude (rad).
  CameraPath(const std::vector<Waypoint>& waypoints, double duration, double wobble, unsigned seed);

  // Camera-to-world pose at time t in [0, duration] (camera: x right, y down, z forward).
  Eigen::Isometry3d pose(double t) const;
  // Spline parameter reached at time t (waypoint i sits at parameter i).
  double paramAt(double t) const { return paramAtEffort(effortAtTime(t)); }
  double duration() const { return duration_; }
  double length() const { return length_; }
  // A hand's tremor on top of the wobble: a few tenths of a degree and a few millimetres at
  // 1-5 Hz, sums of sines with incommensurate frequencies (0: none).
  void setTremor(double degrees, double metres) {
    tremor_rad_ = degrees * M_PI / 180.0;
    tremor_m_ = metres;
  }
  // Eye positions sampled densely, to keep obstacles off the path.
  std::vector<Eigen::Vector3d> samples(double spacing) const;

 private:
  double paramAtDistance(double s) const;
  double paramAtEffort(double e) const;
  double effortAtTime(double t) const;
  Spline eye_, target_;
  // Arc-length table: parameter, metres, and "effort" (metres divided by the segment's pace),
  // which is what the speed profile spends uniformly over time.
  std::vector<double> table_u_, table_s_, table_e_;
  std::vector<double> pace_;
  double effort_ = 0.0;
  double duration_, length_ = 0.0, wobble_;
  double phase_[4];
  double tremor_rad_ = 0.0, tremor_m_ = 0.0;
  double tremor_phase_[12];
};

}  // namespace hiveslam::synth
