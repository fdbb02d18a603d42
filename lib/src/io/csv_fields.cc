#include "diffpd/csv_fields.h"

#include <cstdlib>
#include <sstream>

namespace diffpd {

std::string TrimCsvField(const std::string& s) {
  const size_t b = s.find_first_not_of(" \t\r\n");
  if (b == std::string::npos) return "";
  const size_t e = s.find_last_not_of(" \t\r\n");
  return s.substr(b, e - b + 1);
}

std::vector<std::string> SplitCsvLine(const std::string& line) {
  std::vector<std::string> fields;
  std::string field;
  std::istringstream in(line);
  while (std::getline(in, field, ',')) fields.push_back(TrimCsvField(field));
  if (!line.empty() && line.back() == ',') fields.push_back("");
  return fields;
}

bool ParseCsvNumber(const std::string& field, double* value) {
  if (field.empty()) return false;
  char* end = nullptr;
  *value = std::strtod(field.c_str(), &end);
  return end == field.c_str() + field.size();
}

}  // namespace diffpd
