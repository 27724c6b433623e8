#include "io/text_table.hpp"

#include <charconv>
#include <fstream>

#include "common/error.hpp"

namespace hiveslam::io {

std::vector<TableRow> readTextTable(const std::filesystem::path& path) {
  std::ifstream in(path);
  if (!in) throw InputError("cannot open " + path.string());
  std::vector<TableRow> rows;
  std::string text;
  int number = 0;
  while (std::getline(in, text)) {
    ++number;
    TableRow row{number, {}};
    std::string field;
    for (char c : text) {
      if (c == '#' && row.fields.empty() && field.empty()) break;  // comment line
      if (c == ' ' || c == '\t' || c == ',' || c == '\r') {
        if (!field.empty()) row.fields.push_back(std::move(field));
        field.clear();
      } else {
        field.push_back(c);
      }
    }
    if (!field.empty()) row.fields.push_back(std::move(field));
    if (!row.fields.empty()) rows.push_back(std::move(row));
  }
  return rows;
}

double parseNumber(const std::string& field, const std::filesystem::path& path, int line) {
  double value = 0.0;
  const char* end = field.data() + field.size();
  auto [ptr, ec] = std::from_chars(field.data(), end, value);
  if (ec != std::errc() || ptr != end)
    throw InputError(path.string() + ":" + std::to_string(line) + ": '" + field +
                     "' is not a number");
  return value;
}

}  // namespace hiveslam::io
