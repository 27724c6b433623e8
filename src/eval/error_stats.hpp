#pragma once
// Summary statistics of an error series, with numpy's definitions (median of an even count is
// the mean of the two middle values; std is the population std).
#include <nlohmann/json_fwd.hpp>
#include <vector>

namespace hiveslam::eval {

struct ErrorStats {
  double rmse = 0, mean = 0, median = 0, std = 0, min = 0, max = 0, sse = 0;
  size_t count = 0;
};

ErrorStats summarize(const std::vector<double>& errors);
nlohmann::json toJson(const ErrorStats& stats);

}  // namespace hiveslam::eval
