#pragma once
// A stamped trajectory of camera-to-world poses (T_wc), the unit of exchange between the
// SLAM output, the ground truth readers and the evaluation.
#include <Eigen/Geometry>
#include <vector>

namespace hiveslam::io {

struct Trajectory {
  std::vector<double> stamps;  // seconds
  std::vector<Eigen::Isometry3d> poses;

  size_t size() const { return stamps.size(); }
  bool empty() const { return stamps.empty(); }
  void add(double t, const Eigen::Isometry3d& T_wc) {
    stamps.push_back(t);
    poses.push_back(T_wc);
  }
  // Sum of the distances between consecutive positions.
  double pathLength() const {
    double length = 0.0;
    for (size_t i = 1; i < poses.size(); ++i)
      length += (poses[i].translation() - poses[i - 1].translation()).norm();
    return length;
  }
};

}  // namespace hiveslam::io
