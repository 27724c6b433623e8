#pragma once
// Reads the small text tables every dataset format uses (times files, rgb.txt, csv, TUM
// trajectories): '#' comments and blank lines skipped, fields split on whitespace or commas.
#include <filesystem>
#include <string>
#include <vector>

namespace hiveslam::io {

struct TableRow {
  int line = 0;  // 1-based line number in the file, for error messages
  std::vector<std::string> fields;
};

std::vector<TableRow> readTextTable(const std::filesystem::path& path);

// Parses a field as a number; throws InputError naming file and line when it is not one.
double parseNumber(const std::string& field, const std::filesystem::path& path, int line);

}  // namespace hiveslam::io
