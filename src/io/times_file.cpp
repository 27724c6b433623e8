#include "io/times_file.hpp"

#include "common/error.hpp"
#include "io/image_list_source.hpp"
#include "io/text_table.hpp"

namespace hiveslam::io {

std::vector<double> readTimesFile(const std::filesystem::path& path) {
  if (!std::filesystem::exists(path)) throw InputError("times file not found: " + path.string());
  std::vector<double> stamps;
  std::vector<int> lines;
  for (const auto& row : readTextTable(path)) {
    stamps.push_back(parseNumber(row.fields[0], path, row.line));
    lines.push_back(row.line);
  }
  if (stamps.empty()) throw InputError("times file is empty: " + path.string());
  checkIncreasing(stamps, path, lines);
  return stamps;
}

}  // namespace hiveslam::io
