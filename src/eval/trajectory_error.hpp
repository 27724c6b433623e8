#pragma once
// Absolute and relative trajectory error, evo's definitions (evo_ape / evo_rpe with -a/-as):
// associate, align the estimate onto the reference with Umeyama on the matched positions,
// then measure the translation part.
#include <nlohmann/json_fwd.hpp>
#include <vector>

#include "eval/association.hpp"
#include "eval/error_stats.hpp"
#include "eval/similarity.hpp"
#include "io/trajectory.hpp"

namespace hiveslam::eval {

enum class Alignment { None, SE3, Sim3 };

struct MatchOptions {
  double max_diff = 0.01;      // seconds
  bool by_index = false;       // KITTI: pair line i with line i
  Alignment alignment = Alignment::Sim3;
};

// The angle of a rotation, in degrees (RPE's rotation part, a stretch's turn).
double rotationDegrees(const Eigen::Matrix3d& R);

// The matched, aligned pair both metrics start from.
struct AlignedPair {
  io::Trajectory ref;  // matched reference poses
  io::Trajectory est;  // matched estimate poses, aligned onto ref
  Similarity alignment;
};
AlignedPair matchAndAlign(const io::Trajectory& ref, const io::Trajectory& est,
                          const MatchOptions& options);

struct AteResult {
  ErrorStats stats;
  std::vector<double> errors;  // per matched pose, metres
  AlignedPair pair;
  double reference_length = 0.0;  // path length of the matched reference, metres
};
AteResult computeAte(const io::Trajectory& ref, const io::Trajectory& est,
                     const MatchOptions& options = {});

enum class DeltaUnit { Frames, Meters };
enum class RpeRelation { Translation, RotationDeg };

struct RpeOptions {
  MatchOptions match;
  double delta = 1.0;
  DeltaUnit unit = DeltaUnit::Frames;
  RpeRelation relation = RpeRelation::Translation;
  bool all_pairs = false;
};

struct RpeResult {
  ErrorStats stats;
  std::vector<double> errors;
  std::vector<std::pair<size_t, size_t>> pairs;  // indices into the matched poses
};
RpeResult computeRpe(const io::Trajectory& ref, const io::Trajectory& est, const RpeOptions& options);

std::string toString(Alignment alignment);

}  // namespace hiveslam::eval
