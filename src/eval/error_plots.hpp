#pragma once
// The plots people read a run by: the position error over time, and along each axis (where the
// drift is, and in which direction), from an ATE result.
#include <filesystem>
#include <string>

#include "eval/trajectory_error.hpp"

namespace hiveslam::eval {

// ATE per matched pose against time since the first.
void plotErrorOverTime(const std::filesystem::path& png, const AteResult& ate, const std::string& title);
// The aligned estimate minus the reference, per axis, against time: one chart each for x, y, z.
void plotAxisErrors(const std::filesystem::path& png, const AteResult& ate, const std::string& title);

}  // namespace hiveslam::eval
