// Fields of the comma-separated files the library and its problems read
// (captured motion, recordings): a line is split at every ',', each field
// stripped of surrounding blanks (space, tab, CR, LF); a trailing ',' gives
// a last, empty field. No quoting.
#pragma once

#include <string>
#include <vector>

namespace diffpd {

// s without leading and trailing blanks.
std::string TrimCsvField(const std::string& s);
// The trimmed fields of one line ("" gives no field, "a," gives {"a", ""}).
std::vector<std::string> SplitCsvLine(const std::string& line);
// Parses the whole field as a number (strtod syntax, so "nan" and "inf"
// too); false for an empty field or trailing characters. No range check.
bool ParseCsvNumber(const std::string& field, double* value);

}  // namespace diffpd
